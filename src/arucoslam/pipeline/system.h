// System: the monocular SLAM pipeline behind one call per image: ORB extraction and marker
// detection, then the SLAM of slam/FrameFlow, with keyframes mapped inline (blocking) or on a
// mapping thread; with a known marker map also world anchoring and marker relocalisation.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/map/map.h"
#include "arucoslam/pipeline/bounded_queue.h"
#include "arucoslam/pipeline/mapping_gate.h"
#include "arucoslam/pipeline/marker_frontend.h"
#include "arucoslam/pipeline/system_options.h"
#include "arucoslam/pipeline/system_report.h"
#include "arucoslam/slam/frame_flow.h"

namespace arucoslam {

class System : private MappingControl {
 public:
  System(const CameraModel& camera, const SystemOptions& options = {});
  ~System() override;
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // One 8-bit grey image (distorted, as captured). Timestamps must increase.
  FrameReport ProcessImage(const cv::Mat& grey, double timestamp_s);
  // The same from features already extracted (`undistorted` filled, camera set).
  FrameReport ProcessFrame(Frame frame);
  // The same with the image's marker detections (distorted pixels), used with a marker map.
  FrameReport ProcessFrame(Frame frame, const std::vector<MarkerDetection>& detections);
  // Map reuse: before the first frame, replaces the empty map with a saved one
  // (`world_aligned`: in the marker world frame). No map is initialised over it: frames get
  // no pose until a relocalisation into it succeeds (from markers when aligned, else from
  // keyframe matches). `localize_only`: no keyframe, no mapping, no alignment and no reset;
  // the map's keyframes and points stay as loaded.
  void StartFromMap(MapData map, bool world_aligned, bool localize_only);
  bool localize_only() const { return flow_.localize_only(); }
  // Waits until every queued keyframe is mapped and stops the mapping thread. Called by
  // the destructor; ProcessImage may not be called after it.
  void Finish();

  // Every frame that got a pose, re-expressed relative to its reference keyframe's final
  // pose when that keyframe is still in the map, but those off their keyframes
  // (drop_inconsistent_poses; not checked with a loaded map or for the biggest closed map
  // of a keypoint run). With a marker map: only poses in the world (marker poses, aligned
  // maps, closed maps frozen). Keypoints only: the poses of the map with the most keyframes
  // (maps are in unrelated frames), as ORB-SLAM3 does.
  std::vector<StampedPose> Trajectory() const { return flow_.CheckedTrajectory(nullptr); }
  // Keyframes (in time order) and points of the current map plus, with a marker map, of
  // closed aligned maps.
  std::vector<StampedPose> KeyframePoses() const { return flow_.KeyframePoses(); }
  std::vector<Eigen::Vector3d> MapPoints() const { return flow_.MapPoints(); }
  const Map& map() const { return flow_.map(); }
  TrackingState state() const { return flow_.state(); }
  bool world_aligned() const { return flow_.world_aligned(); }
  // The known markers (fixed as in markers.json) and the ones mapped online (fixed: false).
  // Call after Finish. Empty without a marker map.
  MarkerMap MarkerMapOutput() const { return flow_.marker_mapping().ToMarkerMap(); }
  // Copy of the statistics (the mapping thread adds to local_mapping_ms).
  SystemStats Stats() const;

 private:
  // The frame's markers located by marker_frontend_ into the flow's marker fusion.
  void LocateWithMarkers(Frame& frame, const std::vector<MarkerDetection>& detections,
                         FrameReport& report);
  // One keyframe's local mapping, timed (mapping thread, or inline after the frame).
  void MapKeyframe(KeyframeId keyframe);
  void StartMappingThread();
  void StopMappingThread();

  // MappingControl: the flow's keyframes go to pending_keyframe_ (blocking) or queue_.
  bool Idle() const override;
  bool HasRoom() const override;
  bool Submit(KeyframeId keyframe) override;
  void WaitUntilMapped() override;
  void Pause() override { StopMappingThread(); }
  void Resume() override;
  void Hold() override;
  void Release() override;
  bool YieldRequested() const override {
    return queue_ && (queue_->Size() > 0 || gate_.HoldRequested());
  }

  CameraModel camera_;
  SystemOptions options_;
  OrbExtractor extractor_;
  mutable std::mutex stats_mutex_;
  SystemStats stats_;
  FrameFlow flow_;
  std::unique_ptr<MarkerFrontend> marker_frontend_;  // with a marker map only
  std::size_t num_frames_ = 0;
  std::optional<KeyframeId> pending_keyframe_;  // blocking mode: to map after tracking

  std::unique_ptr<BoundedQueue<KeyframeId>> queue_;
  std::thread mapping_thread_;
  MappingGate gate_;  // Hold / Release between two keyframes
  std::atomic<bool> mapping_busy_{false};
  // Threaded mode: keyframes pushed to queue_ and keyframes the mapping thread finished,
  // both counted from StartMappingThread (synchronous_young_map_keyframes).
  std::size_t keyframes_queued_ = 0;
  std::size_t keyframes_mapped_ = 0;  // guarded by mapped_mutex_
  std::mutex mapped_mutex_;
  std::condition_variable mapped_;
  bool finished_ = false;
};

}  // namespace arucoslam
