// MapSession: what becomes of a map when tracking is lost and stays lost (reset, closed, merged
// into the next map in the world, the gap bridged), and the backfill of a new map's first frames.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "arucoslam/geometry/pose_consistency.h"
#include "arucoslam/geometry/world_motion_prior.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/optim/essential_graph.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/tracker.h"

namespace arucoslam {

struct MapSessionOptions {
  // Tracking lost while the map holds at most this many keyframes (and is not in the marker
  // world): the map is discarded and initialisation starts over (a young map is cheaper to
  // rebuild than to recover).
  int reset_max_keyframes = 5;
  // A world-aligned map lost for this many frames in a row while markers give poses that the
  // map does not take back: it is closed and a new one initialised (frames).
  int marker_reset_lost_frames = 10;
  // Tracking lost for this long and not relocalised: the map is closed and a new one started
  // (seconds).
  double new_map_after_lost_s = 1.0;
  // A world-aligned map closed after a loss is kept whole and merged into the next map as
  // soon as that one is in the world too (one map again: relocalisation and loops reach the
  // old places, a saved map and the final adjustment hold both). false: its poses are frozen
  // and it stays in the outputs only.
  bool merge_closed_maps = true;

  // Bridge over a tracking gap: the camera's motion over the closed map's last
  // bridge_motion.max_span_s predicts (constant velocity) the world pose of the next map's
  // first keyframe, if that keyframe comes at most bridge_motion.max_age_s after the closed
  // map's last pose. Once both maps are merged in the world, the prediction is a prior of
  // that keyframe in one pose-graph correction of the new map (the absorbed map held).
  bool bridge_tracking_gaps = true;
  WorldMotionPriorOptions bridge_motion{.max_age_s = 3.0, .min_span_s = 0.3, .max_span_s = 1.0};
  // The prior's position sigma: bridge_position_sigma_m (metres) plus
  // bridge_position_sigma_per_s (metres per second) times the gap (seconds). 0.1 m per
  // second: a robot at 0.7 m/s that starts turning at 0.4 rad/s strays 0.14 m from the
  // straight line in a second.
  double bridge_position_sigma_m = 0.025;
  double bridge_position_sigma_per_s = 0.1;
  // Its rotation sigma: bridge_rotation_sigma_rad (radians) plus bridge_rotation_sigma_per_s
  // (radians per second) times the gap; a turn in the gap is not predicted.
  double bridge_rotation_sigma_rad = 0.05;
  double bridge_rotation_sigma_per_s = 0.5;
  // After that correction the predicted camera centre stays a prior of the keyframe in every
  // bundle adjustment of the whole map, with the position sigma bridge_position_sigma_m +
  // bridge_max_acceleration_m_s2 (metres per second squared) * gap^2 / 2: how far a vehicle
  // can stray from the prediction (the pose graph's tighter sigma would pull a right map
  // towards a wrong prediction).
  bool bridge_in_bundle_adjustment = true;
  double bridge_max_acceleration_m_s2 = 0.3;

  // Frames between the initialisation reference and the frame that initialised a map, and
  // before them the frames the previous map lost before it was reset, are tracked backwards
  // against the new map and get poses too: up to this many frames, the newest kept. 0: none.
  int max_backfill_frames = 150;

  bool Check(std::string* why = nullptr) const;
};

struct MapSessionStats {
  int num_resets = 0;               // maps replaced by a new one (discarded or closed)
  int num_new_maps_after_loss = 0;  // ... because tracking stayed lost new_map_after_lost_s
  int num_maps_discarded = 0;       // closed maps never aligned (marker world only)
  int num_map_merges = 0;           // closed maps absorbed by a later map in the world
  int num_bridged_gaps = 0;         // merged maps corrected with a bridge over their gap
};

// What the session needs to know of the map that lost the current frame.
struct LostMapState {
  std::size_t num_keyframes = 0;
  bool world_aligned = false;         // the map is in the marker world
  bool frame_has_marker_fix = false;  // the lost frame has a usable marker location
  bool loaded = false;                // a saved map: kept, frames relocalise into it
};

// What to do with the map after a lost frame.
enum class LossAction {
  kKeep,    // keep it: tracking may still relocalise into it
  kReset,   // reset it now (young, or markers keep locating frames it does not take back)
  kNewMap,  // reset it now: lost for new_map_after_lost_s
};

// What closing the current map keeps (asked before the map is replaced).
enum class MapClosing {
  kNothing,             // no keyframe, or a keypoint map smaller than a closed one
  kBiggestKeypointMap,  // keypoints only: its poses become the output (KeepBiggestKeypointMap)
  kDiscarded,           // never aligned to the marker world: its poses are dropped
  kInWorld,             // world-aligned: closed into the outputs (CloseWorldMap)
};

// A world-aligned map being closed, as its owner sees it.
struct ClosingWorldMap {
  // The map's frame poses in the world with frames off their keyframes left out, in time
  // order: the camera's motion at its end (the bridge's prediction).
  std::vector<StampedPose> motion_poses;
  // The outputs of every closed map with this one's added: keyframes in time order, points.
  std::vector<StampedPose> keyframes;
  std::vector<Eigen::Vector3d> points;
  // The marker location of each of its keyframes that had one.
  std::map<KeyframeId, MarkerFix> keyframe_fixes;
};

// What a merge of the closed map into the current one brought.
struct MergedClosedMap {
  AbsorbedIds ids;             // the closed map's ids -> their new ids in the current map
  KeyframeId attached_to;      // the current keyframe its spanning tree hangs under
  int marker_generation = -1;  // the marker mapper's generation of the closed map
  std::map<KeyframeId, MarkerFix> keyframe_fixes;  // its keyframes' fixes, under new ids
};

class MapSession {
 public:
  // `marker_world`: a marker map is given (maps are kept only in its world); else maps are
  // in unrelated frames and the biggest one is the output.
  MapSession(const MapSessionOptions& options, bool marker_world);

  const MapSessionOptions& options() const { return options_; }
  const MapSessionStats& stats() const { return stats_; }

  // Loss (map_session.cc). A lost frame of the current loss; the frames the markers did not
  // locate are kept for the next map's backfill.
  LossAction OnLostFrame(const Frame& frame, const LostMapState& map);
  // A frame was tracked: the loss, if any, is over.
  void OnTrackedFrame();

  // Closing (map_session.cc), when the map is about to be replaced: what is kept of it (an
  // unaligned map in the marker world is counted as discarded).
  MapClosing DecideClosing(std::size_t num_keyframes, bool world_aligned);
  // Keypoints only, after kBiggestKeypointMap: the closing map's frame `poses` (its own frame)
  // are the output until a bigger map comes.
  void KeepBiggestKeypointMap(std::vector<StampedPose> poses, std::size_t num_keyframes);
  // The world-aligned `map` closes: its outputs are kept and, with merge_closed_maps, the map
  // itself until the next map is in the world. True when it is kept for a merge.
  bool CloseWorldMap(const Map& map, ClosingWorldMap closing);
  // The map was replaced by an empty one. `closed_marker_generation`: the marker mapper's
  // generation of the map CloseWorldMap kept for a merge at this reset (nullopt: none kept).
  void StartNewMap(std::optional<int> closed_marker_generation);

  // Outputs of the closed maps. Keypoints only: the biggest closed map's poses, when it has
  // more keyframes than `current_keyframes` (else null).
  const std::vector<StampedPose>* BiggerClosedMapPoses(std::size_t current_keyframes) const;
  const std::vector<StampedPose>& closed_keyframes() const { return closed_keyframes_; }
  const std::vector<Eigen::Vector3d>& closed_points() const { return closed_points_; }

  // Merge (map_session_merge.cc). Once the current map is in the world: the closed map kept
  // for a merge joins it (MapData::Absorb, under the current keyframe nearest its first one)
  // and leaves the closed outputs. nullopt: nothing was merged.
  std::optional<MergedClosedMap> MergeClosedMap(Map& map);
  // Keyframes the current map absorbed from closed ones (already in the world).
  const std::set<KeyframeId>& absorbed_keyframes() const { return absorbed_keyframes_; }
  // Whether a point of `map` links an absorbed keyframe to one of the map's own.
  bool LinkedToAbsorbedMap(const Map& map) const;

  // Bridge (map_session_bridge.cc). The current map's keyframe `keyframe` at `timestamp_s`,
  // inserted before the map is in the world while a closed map waits for the merge: the
  // closed map's motion predicts its pose, a bridge prior.
  void AddBridgePrior(KeyframeId keyframe, double timestamp_s, bool world_aligned);
  bool HasBridgePriors() const { return !bridge_priors_.empty(); }
  const std::vector<KeyframePosePrior>& bridge_priors() const { return bridge_priors_; }
  const std::vector<KeyframePosePrior>& bridge_adjustment_priors() const {
    return bridge_adjustment_priors_;
  }
  // After a merge: `map` corrected by the pose graph (`graph`) with `marker_priors` and the
  // bridge priors, the absorbed keyframes held. The bridge priors are used up; once applied,
  // with bridge_in_bundle_adjustment, their adjustment sigma versions join the held ones.
  EssentialGraphResult CorrectAcrossBridge(Map& map, std::vector<KeyframePosePrior> marker_priors,
                                           const EssentialGraphOptions& graph);
  // Bridge priors already applied, for the whole-map bundle adjustments until the next reset.
  const std::vector<KeyframePosePrior>& held_bridge_priors() const { return held_bridge_priors_; }

  // Backfill (map_session_backfill.cc). Keeps `frame` for the next initialisation's backfill;
  // the oldest go beyond max_backfill_frames.
  void KeepForBackfill(const Frame& frame);
  // The frames kept, tracked backwards in time against `map` from `second` (the frame that
  // initialised it, keyframe `second_id`) by a tracker of their own (`tracking`, the map left
  // as it is), each referenced to `first_id`; returns the tracked ones, newest first, with
  // their poses and matches. The kept frames are used up.
  std::vector<Frame> TrackBackfill(Map& map, const TrackerOptions& tracking, const Frame& second,
                                   KeyframeId first_id, KeyframeId second_id);

 private:
  struct ClosedMap {
    MapData data;
    int marker_generation = -1;
    std::map<KeyframeId, MarkerFix> keyframe_fixes;
    std::size_t output_keyframes_before = 0;  // closed_keyframes_ entries of older maps
    std::size_t output_points_before = 0;
  };

  bool LostTooLong(double timestamp_s);
  void KeepLostFrame(const Frame& frame);  // for the backfill of the map after this loss

  MapSessionOptions options_;
  bool marker_world_ = false;
  MapSessionStats stats_;

  int lost_with_markers_ = 0;           // lost frames in a row that markers located
  std::optional<double> lost_since_s_;  // timestamp of the first lost frame of this loss

  // Keypoints only: the biggest closed map's poses; with markers, the closed world-aligned
  // maps' keyframes and points (their frame poses stay with the owner, frozen).
  std::vector<StampedPose> biggest_closed_poses_;
  std::size_t biggest_closed_keyframes_ = 0;
  std::vector<StampedPose> closed_keyframes_;
  std::vector<Eigen::Vector3d> closed_points_;
  // The last world-aligned map closed, kept whole until the next map is in the world and
  // absorbs it; the closed outputs above end with its keyframes and points.
  std::optional<ClosedMap> closed_map_;
  std::set<KeyframeId> absorbed_keyframes_;

  // The closed map's last world poses, and the current map's bridge priors: with the pose
  // graph's sigmas, and with the bundle adjustments' (bridge_max_acceleration_m_s2).
  WorldMotionPrior motion_at_close_;
  std::vector<KeyframePosePrior> bridge_priors_;
  std::vector<KeyframePosePrior> bridge_adjustment_priors_;
  std::vector<KeyframePosePrior> held_bridge_priors_;

  std::vector<Frame> initialisation_frames_;  // for the current initialisation's backfill
  std::vector<Frame> lost_frames_;            // of the current loss, for the next backfill
};

}  // namespace arucoslam
