// System: where each image's markers are searched (MarkerSearchPlanner: the whole image, or
// regions around the markers expected from the previous frame's pose in the marker world).
#include "arucoslam/pipeline/system.h"

namespace arucoslam {

std::optional<std::vector<cv::Rect>> System::MarkerSearchRegions() {
  const std::shared_ptr<const MarkerMap> locating = LocatingMarkers();
  std::optional<std::vector<cv::Rect>> regions =
      marker_search_->Next(locating ? *locating : *options_.marker_map);
  if (!regions) {
    std::lock_guard lock(stats_mutex_);
    ++stats_.num_full_marker_scans;
  }
  return regions;
}

void System::RememberMarkerView(const FrameReport& report,
                                const std::vector<MarkerDetection>& detections) {
  std::optional<Rigid3> cam_from_world;  // in the marker world
  if (report.cam_from_world && (report.world_aligned || report.marker_pose)) {
    cam_from_world = *report.cam_from_world;
  } else if (marker_fusion_.fix()) {
    cam_from_world = marker_fusion_.fix()->world_from_cam.Inverse();
  }
  marker_search_->Remember(cam_from_world, detections);
}

}  // namespace arucoslam
