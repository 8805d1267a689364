// PlaceRecognition: the bag-of-words side of a running System for one map: the keyframe
// database, relocalisation of lost frames, loop detection and closing, and global BA.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "arucoslam/feature/vocabulary.h"
#include "arucoslam/map/map.h"
#include "arucoslam/optim/global_bundle_adjustment.h"
#include "arucoslam/pipeline/bounded_queue.h"
#include "arucoslam/slam/keyframe_database.h"
#include "arucoslam/slam/loop_closer.h"
#include "arucoslam/slam/loop_detector.h"
#include "arucoslam/slam/place_index.h"
#include "arucoslam/slam/relocalizer.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

struct PlaceRecognitionOptions {
  bool loop_closing = true;  // false: database and relocalisation only
  KeyframeDatabaseOptions database;
  RelocalizerOptions relocalizer;
  LoopDetectorOptions detector;
  LoopCloserOptions closer;
  // After each closed loop: a global bundle adjustment (on its own thread unless blocking).
  bool global_bundle_adjustment = true;
  GlobalBundleAdjustmentOptions global_ba;
  int loop_queue_capacity = 64;  // mapped keyframes waiting for the loop-closing thread
  // Marker ids as place words: when the database finds no pose for a lost frame, up to this
  // many keyframes that saw the frame's markers (most shared ids first) are tried. 0: off.
  int max_marker_candidates = 5;

  bool Check(std::string* why = nullptr) const;
};

// One closed loop, for logs and for checking it against ground truth.
struct ClosedLoop {
  double current_timestamp_s = 0.0;    // the new keyframe
  double candidate_timestamp_s = 0.0;  // the old keyframe it was matched to
  Sim3 candidate_from_current;         // as solved, in map units before the correction
  int num_inliers = 0;                 // Sim3 inliers plus projected matches
  double detection_to_corrected_ms = 0.0;
};

struct PlaceRecognitionStats {
  int num_relocalizations = 0;         // lost frames relocalised from the database
  int num_relocalization_attempts = 0;
  TimingStats relocalization_ms;       // per attempt
  TimingStats loop_detection_ms;       // per mapped keyframe: database + detection
  // Place-database matches of mapped keyframes outside their neighbourhood, before the
  // consistency check: look-alike places (or true loops) the detector had to judge.
  int num_loop_database_matches = 0;
  int num_loop_candidates = 0;         // consistent candidates verified
  int num_loops_rejected = 0;          // candidates LoopCloser refused
  std::vector<ClosedLoop> loops;       // closed loops, in order
  TimingStats loop_correction_ms;      // detection -> corrected map, per closed loop
  int num_global_bundle_adjustments = 0;  // applied to the map
  int num_global_bundle_adjustments_discarded = 0;  // the map was changed under them
  TimingStats global_bundle_adjustment_ms;          // snapshot to applied, per run
};

// Thread safety: Relocalize runs on the tracking thread, KeyframeMapped on the mapping thread;
// the database has its own lock. Map edits by local mapping and by loop closing are serialised
// with LockMapEdits (local mapping waits while a loop is being closed).
class PlaceRecognition final : public PlaceIndex {
 public:
  // `threaded`: loop closing and global BA run on their own threads; otherwise inline in
  // KeyframeMapped. Statistics are added to `stats` under `stats_mutex`.
  PlaceRecognition(Map& map, std::shared_ptr<const Vocabulary> vocabulary,
                   const PlaceRecognitionOptions& options, bool threaded,
                   PlaceRecognitionStats* stats, std::mutex* stats_mutex);
  ~PlaceRecognition() override;
  PlaceRecognition(const PlaceRecognition&) = delete;
  PlaceRecognition& operator=(const PlaceRecognition&) = delete;

  // Pose of a lost frame from the database (frame features undistorted); nullopt when none.
  std::optional<RelocalizationResult> Relocalize(const Frame& frame) override;
  // Counted in PlaceRecognitionStats::num_relocalizations.
  void RelocalizationTaken() override;
  // Every keyframe already in the map enters the database (a map loaded from a file).
  void IndexExistingKeyframes() override;
  // ... or these (keyframes of a map merged into this one).
  void IndexKeyframes(const std::vector<KeyframeId>& keyframes) override;
  // A keyframe finished local mapping: it enters the database and the loop detector.
  void KeyframeMapped(KeyframeId keyframe) override;
  // Held by local mapping for each keyframe, and by loop closing and world alignment.
  std::unique_lock<std::mutex> LockMapEdits() override { return std::unique_lock(edit_mutex_); }
  // The map was moved from outside (world alignment) while holding LockMapEdits: a running
  // global BA is discarded.
  void MapMovedExternally() override;
  // The loop closer keeps the monocular scale fixed once the map is metric (markers).
  void SetMetricMap(bool metric) override;
  // Once the map is in the marker world: the markers whose corner views join global BA (known
  // ones fixed, mapped ones estimated). Call it holding LockMapEdits; the landmarks are read
  // and written only under that lock. Null: keypoints only.
  void SetMarkerLandmarks(MarkerLandmarks* landmarks) override { marker_landmarks_ = landmarks; }
  // Camera-centre priors that join global BA (the bridge over a tracking gap). Call it
  // holding LockMapEdits, like SetMarkerLandmarks.
  void SetBundleAdjustmentPriors(std::vector<KeyframePosePrior> priors) override {
    bundle_adjustment_priors_ = std::move(priors);
  }
  // ... and the marker pose priors for the loops' essential graphs (LoopCloser::SetPosePriors;
  // the source is called on the loop-closing thread).
  void SetLoopPosePriors(LoopCloser::PosePriorSource source,
                         const EssentialGraphOptions& graph) override {
    closer_.SetPosePriors(std::move(source), graph);
  }
  // Incremented by each closed loop and applied global BA: the tracking thread re-anchors
  // its last pose to its reference keyframe when this changes.
  std::uint64_t corrections() const override { return corrections_; }
  // Product of the scale changes that closed loops applied around `keyframe` (1 when none;
  // kept for culled keyframes). A pose held relative to the keyframe since this was `then`
  // has its offset multiplied by KeyframeScale / then.
  double KeyframeScale(KeyframeId keyframe) const override;
  // Multiplies the keyframes' KeyframeScale by a correction's scale changes (closed loops
  // here; the System's marker drift corrections from outside).
  void RecordScaleChanges(const std::map<KeyframeId, double>& changes) override;
  // Waits for queued keyframes and a running global BA; idempotent.
  void Finish() override;

 private:
  void AddToDatabase(KeyframeId keyframe);
  void DetectAndClose(KeyframeId keyframe);
  void RequestGlobalBundleAdjustment();
  void RunGlobalBundleAdjustmentOnce();
  void GlobalBundleAdjustmentLoop();

  Map& map_;
  std::shared_ptr<const Vocabulary> vocabulary_;
  PlaceRecognitionOptions options_;
  bool threaded_;
  PlaceRecognitionStats* stats_;
  std::mutex* stats_mutex_;

  mutable std::mutex database_mutex_;
  KeyframeDatabase database_;
  std::vector<KeyframeId> stored_;  // keyframes in the database (culled ones are erased)
  Relocalizer relocalizer_;
  LoopDetector detector_;
  LoopCloser closer_;
  MarkerLandmarks* marker_landmarks_ = nullptr;  // guarded by edit_mutex_
  std::vector<KeyframePosePrior> bundle_adjustment_priors_;  // under LockMapEdits

  std::mutex edit_mutex_;
  std::uint64_t epoch_ = 0;  // under edit_mutex_: bumped by every change a global BA cannot merge
  std::atomic<std::uint64_t> corrections_{0};
  mutable std::mutex scale_mutex_;
  std::map<KeyframeId, double> keyframe_scales_;  // see KeyframeScale

  std::unique_ptr<BoundedQueue<KeyframeId>> queue_;
  std::thread loop_thread_;
  std::mutex ba_mutex_;
  std::condition_variable ba_wake_;
  bool ba_requested_ = false;
  bool ba_stop_ = false;
  std::thread ba_thread_;
  bool finished_ = false;
};

}  // namespace arucoslam
