// FrameFlow's current map: its objects lent to the map lifecycle (slam/map_lifecycle.h) and
// the marker world (slam/marker_world.h), the localisation in a loaded map, and the
// replacement of a lost map.
#include <memory>
#include <utility>

#include "arucoslam/slam/frame_flow.h"

namespace arucoslam {

MapLifecycleParts FrameFlow::Parts() {
  return {*map_, *tracker_, pose_history_, anchoring_, marker_fusion_, marker_mapping_};
}

MarkerWorldParts FrameFlow::MarkerParts() {
  return {*map_,          *tracker_,       *mapper_,   pose_history_, anchoring_,
          marker_fusion_, marker_mapping_, lifecycle_, *mapping_};
}

void FrameFlow::MakeLocalMapper() {
  mapper_ = std::make_unique<LocalMapper>(*map_, options_.mapper);
  if (options_.marker_map) {  // keyframes anchoring_ keeps are not culled
    mapper_->SetKeyframeGuard(
        [this](const Keyframe& keyframe) { return anchoring_.KeepsKeyframe(keyframe); });
  }
  if (!options_.inline_mapping && options_.yield_bundle_adjustment) {
    mapper_->SetYieldRequest([this] { return mapping_->YieldRequested(); });
  }
}

void FrameFlow::StartFromMap(MapData map, bool world_aligned, bool localize_only) {
  lifecycle_.StartFromMap(Parts(), std::move(map), world_aligned, localize_only);
}

void FrameFlow::LocalizeInLoadedMap(Frame& frame, FrameReport& report) {
  report.state = TrackingState::kNotInitialized;
  if (!marker_world_.Relocalize(MarkerParts(), frame, report) &&
      !lifecycle_.RelocalizeWithPlaces(Parts(), frame, report) &&
      !lifecycle_.RelocalizeInLoadedMap(Parts(), frame, report)) {
    report.message = "not localised in the loaded map";
    return;
  }
  last_state_ = TrackingState::kTracking;
  frames_since_keyframe_ = 0;
  report.state = TrackingState::kTracking;
  report.cam_from_world = frame.cam_from_world;
  RecordPose(frame, tracker_->reference_keyframe());
}

void FrameFlow::HandleLostFrame(const Frame& frame, std::size_t frame_index) {
  if (lifecycle_.OnLostFrame(Parts(), frame, frame_index)) ResetMap();
}

void FrameFlow::ResetMap() {
  mapping_->Pause();
  const bool kept_for_merge = lifecycle_.CloseMap(Parts());
  tracker_.reset();
  mapper_.reset();
  map_ = std::make_unique<Map>();
  tracker_ = std::make_unique<Tracker>(*map_, options_.tracker);
  MakeLocalMapper();
  lifecycle_.StartNewMap(Parts(), kept_for_merge);
  map_initializer_.Reset();
  anchoring_.Reset();
  marker_fusion_.MapReset();
  last_state_ = TrackingState::kNotInitialized;
  mapping_->Resume();
}

}  // namespace arucoslam
