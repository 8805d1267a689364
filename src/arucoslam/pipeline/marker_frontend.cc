#include "arucoslam/pipeline/marker_frontend.h"

#include <utility>

namespace arucoslam {

MarkerFrontend::MarkerFrontend(const CameraModel& camera, const DetectorOptions& detector,
                               const MarkerSearchOptions& search)
    : detector_(detector), worker_(detector_), search_(camera, detector, search) {}

void MarkerFrontend::StartDetection(const cv::Mat& grey, const MarkerMap& markers) {
  std::optional<std::vector<cv::Rect>> regions = search_.Next(markers);
  if (!regions) {
    std::lock_guard lock(stats_mutex_);
    ++stats_.num_full_scans;
  }
  worker_.Start(grey, std::move(regions));
}

std::vector<MarkerDetection> MarkerFrontend::WaitForDetections() {
  const Stopwatch waiting;
  TimedDetections detected = worker_.Wait();
  wait_ms_ = waiting.ElapsedMilliseconds();
  detection_ms_ = detected.wall_ms;
  return std::move(detected.detections);
}

void MarkerFrontend::AbandonDetection() {
  try {
    worker_.Wait();
  } catch (...) {
  }
}

void MarkerFrontend::Locate(const std::vector<MarkerDetection>& detections,
                            const MarkerMap& markers, const MapPrediction& prediction,
                            std::size_t frame_index, Frame* frame, MarkerFusion* fusion) {
  const Stopwatch watch;
  frame->markers.clear();
  for (const MarkerDetection& detection : detections) {
    frame->markers.push_back({MarkerId(detection.id), detection.corners});
  }
  fusion->Locate(detections, markers, frame->timestamp_s, prediction, frame_index);
  const double locating_ms = watch.ElapsedMilliseconds();
  std::lock_guard lock(stats_mutex_);
  stats_.marker_ms.Add(detection_ms_ + locating_ms);
  stats_.wait_ms.Add(wait_ms_ + locating_ms);
  detection_ms_ = wait_ms_ = 0.0;
}

void MarkerFrontend::RememberFrame(const FrameReport& report, const std::optional<MarkerFix>& fix,
                                   const std::vector<MarkerDetection>& detections) {
  std::optional<Rigid3> cam_from_world;  // in the marker world
  if (report.cam_from_world && (report.world_aligned || report.marker_pose)) {
    cam_from_world = *report.cam_from_world;
  } else if (fix) {
    cam_from_world = fix->world_from_cam.Inverse();
  }
  search_.Remember(cam_from_world, detections);
}

MarkerFrontendStats MarkerFrontend::stats() const {
  std::lock_guard lock(stats_mutex_);
  return stats_;
}

}  // namespace arucoslam
