// System: the monocular SLAM pipeline behind one call per image: ORB extraction, map
// initialisation, tracking, keyframe insertion and local mapping, blocking or on two threads.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/map/map.h"
#include "arucoslam/pipeline/bounded_queue.h"
#include "arucoslam/slam/initializer.h"
#include "arucoslam/slam/keyframe_policy.h"
#include "arucoslam/slam/local_mapper.h"
#include "arucoslam/slam/map_initialization.h"
#include "arucoslam/slam/tracker.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

struct SystemOptions {
  OrbExtractorOptions extractor;
  InitializerOptions initializer;
  InitialMapOptions initial_map;
  TrackerOptions tracker;
  KeyframePolicyOptions keyframes;
  LocalMapperOptions mapper;
  // true: each frame is tracked and its keyframe mapped in the caller's thread before
  // ProcessImage returns (deterministic). false: local mapping runs on its own thread.
  bool blocking = true;
  int mapper_queue_capacity = 3;  // keyframes waiting for the mapping thread
  // The initialisation reference frame is replaced when the current frame is more than this
  // many seconds later (a reference is also replaced when too few matches are left). Long
  // enough for a vehicle that starts from rest to build up parallax.
  double max_initialization_gap_s = 3.0;
  // Tracking lost while the map holds at most this many keyframes: the map is discarded and
  // initialisation starts over (a young map is cheaper to rebuild than to recover).
  int reset_max_keyframes = 5;

  bool Check() const;
};

struct FrameReport {
  std::size_t index = 0;  // 0-based count of frames given to the System
  double timestamp_s = 0.0;
  TrackingState state = TrackingState::kNotInitialized;
  std::optional<Rigid3> cam_from_world;  // as estimated when the frame was tracked
  bool initialized_map = false;          // this frame completed map initialisation
  bool new_keyframe = false;
  int num_features = 0;
  int num_inliers = 0;
  std::string message;  // initialisation outcome or loss, for logs
};

struct SystemStats {
  TimingStats extraction_ms;     // per frame
  TimingStats tracking_ms;       // per frame: initialisation or tracking + keyframe decision
                                 // (no extraction, no local mapping)
  TimingStats frame_ms;          // per frame, everything on the tracking thread
  TimingStats local_mapping_ms;  // per keyframe
  int num_frames = 0;
  int num_tracked = 0;           // frames with a pose
  int num_lost = 0;              // frames in state lost
  int num_losses = 0;            // transitions tracking -> lost
  int num_initialization_attempts = 0;
  int num_initializations = 0;
  int num_resets = 0;
  int num_keyframes_inserted = 0;
};

struct StampedPose {
  double timestamp_s = 0.0;
  Rigid3 world_from_cam;
};

class System {
 public:
  System(const CameraModel& camera, const SystemOptions& options = {});
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // One 8-bit grey image (distorted, as captured). Timestamps must increase.
  FrameReport ProcessImage(const cv::Mat& grey, double timestamp_s);
  // The same from features already extracted (`undistorted` filled, camera set).
  FrameReport ProcessFrame(Frame frame);
  // Waits until every queued keyframe is mapped and stops the mapping thread. Called by
  // the destructor; ProcessImage may not be called after it.
  void Finish();

  // Every frame that got a pose, re-expressed relative to its reference keyframe's final
  // pose when that keyframe is still in the map.
  std::vector<StampedPose> Trajectory() const;
  std::vector<StampedPose> KeyframePoses() const;
  std::vector<Eigen::Vector3d> MapPoints() const;
  const Map& map() const { return *map_; }
  TrackingState state() const { return tracker_ ? tracker_->state() : TrackingState::kNotInitialized; }
  // Copy of the statistics (the mapping thread adds to local_mapping_ms).
  SystemStats Stats() const;

 private:
  struct TrackedPose {
    double timestamp_s = 0.0;
    KeyframeId reference;
    Rigid3 cam_from_reference;
    Rigid3 cam_from_world;
  };

  void Initialize(Frame& frame, FrameReport& report);
  void Track(Frame& frame, FrameReport& report);
  void MaybeInsertKeyframe(const Frame& frame, int num_inliers, FrameReport& report);
  void MapKeyframe(KeyframeId keyframe);
  void RecordPose(const Frame& frame, KeyframeId reference);
  void ResetMap();
  void StartMappingThread();
  void StopMappingThread();
  bool MapperIdle() const;

  CameraModel camera_;
  SystemOptions options_;
  OrbExtractor extractor_;
  Initializer initializer_;
  std::unique_ptr<Map> map_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<LocalMapper> mapper_;
  std::optional<Frame> init_reference_;
  std::size_t num_frames_ = 0;
  int frames_since_keyframe_ = 0;
  TrackingState last_state_ = TrackingState::kNotInitialized;
  std::vector<TrackedPose> poses_;
  std::optional<KeyframeId> pending_keyframe_;  // blocking mode: to map after tracking

  std::unique_ptr<BoundedQueue<KeyframeId>> queue_;
  std::thread mapping_thread_;
  std::atomic<bool> mapping_busy_{false};
  bool finished_ = false;

  mutable std::mutex stats_mutex_;
  SystemStats stats_;
};

}  // namespace arucoslam
