// System's map reuse: starting from a saved map, the localisation-only mode, and the
// relocalisation into a loaded map from keyframe matches (slam/loaded_map_relocalizer.h).
#include <optional>
#include <stdexcept>
#include <utility>

#include "arucoslam/pipeline/system.h"

namespace arucoslam {

void System::StartFromMap(MapData map, bool world_aligned, bool localize_only) {
  if (num_frames_ != 0 || finished_) {
    throw std::logic_error("System::StartFromMap after the first frame");
  }
  if (map.NumKeyframes() == 0) throw std::invalid_argument("System::StartFromMap: empty map");
  map_->Write([&map](MapData& data) { data = std::move(map); });
  map_loaded_ = true;
  localize_only_ = localize_only;
  anchoring_.StartLoadedMap(world_aligned);
  if (places_) {
    places_->SetMetricMap(world_aligned);
    places_->IndexExistingKeyframes();
  }
}

void System::LocalizeInLoadedMap(Frame& frame, FrameReport& report) {
  report.state = TrackingState::kNotInitialized;
  if (!RelocalizeWithMarkers(frame, report) && !RelocalizeWithPlaces(frame, report) &&
      !RelocalizeInLoadedMap(frame, report)) {
    report.message = "not localised in the loaded map";
    return;
  }
  last_state_ = TrackingState::kTracking;
  frames_since_keyframe_ = 0;
  report.state = TrackingState::kTracking;
  report.cam_from_world = frame.cam_from_world;
  RecordPose(frame, tracker_->reference_keyframe());
}

bool System::RelocalizeInLoadedMap(Frame& frame, FrameReport& report) {
  // Brute-force keyframe matching, for a loaded map without a place database only.
  if (!map_loaded_ || places_) return false;
  const std::optional<int> num_inliers =
      loaded_map_relocalizer_.Relocalize(*map_, *tracker_, frame, report.index);
  if (!num_inliers) return false;
  report.num_inliers = *num_inliers;
  report.message = "relocalised in the loaded map";
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_map_relocalizations;
  return true;
}

}  // namespace arucoslam
