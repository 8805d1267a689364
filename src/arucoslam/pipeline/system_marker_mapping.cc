// System's marker mapping: once the keypoint map is in the marker world, every keyframe's
// marker observations go to a MarkerMapper (known markers fixed, unknown ones mapped online),
// whose landmarks join local bundle adjustment; a map is adjusted as a whole with every marker
// view when it is closed and at the end of the run.
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

MarkerMapper& System::EnsureMarkerMapper() {
  if (!marker_mapper_) {
    MarkerMapperOptions mapping = options_.marker_mapping;
    mapping.map_unknown = mapping.map_unknown && options_.map_unknown_markers;
    marker_mapper_ = std::make_unique<MarkerMapper>(*options_.marker_map, mapping);
  }
  return *marker_mapper_;
}

void System::StartMarkerMapping() {
  if (!options_.marker_map) return;
  EnsureMarkerMapper();
  marker_mapping_live_ = true;
  if (options_.markers_in_local_ba) {
    mapper_->SetMarkerLandmarks(marker_mapper_->mutable_landmarks());
    // The caller holds the places' edit lock (LockPlacesForMapMove).
    if (places_) places_->SetMarkerLandmarks(marker_mapper_->mutable_landmarks());
  }
  if (places_ && options_.world_anchoring.priors_in_loops) {
    places_->SetLoopPosePriors([this] { return anchoring_.KnownMarkerPriors(); },
                               options_.world_anchoring.marker_correction_graph);
  }
  // Keyframes mapped before the alignment are recorded now, at their aligned poses.
  const std::vector<KeyframeId> keyframes = map_->Read([&](const MapData& data) {
    std::vector<KeyframeId> ids;
    for (const auto& [id, keyframe] : data.keyframes()) {
      if (!marker_mapper_->Records(id)) ids.push_back(id);
    }
    return ids;
  });
  for (const KeyframeId& id : keyframes) FeedMarkerMapping(id);
}

void System::FeedMarkerMapping(KeyframeId keyframe) {
  if (!marker_mapping_live_) return;
  struct Seen {
    Rigid3 cam_from_world;
    CameraModel camera;
    std::vector<MarkerObservation> markers;
  };
  const std::optional<Seen> seen = map_->Read([&](const MapData& data) -> std::optional<Seen> {
    marker_mapper_->SyncKeyframes(data);
    const Keyframe* found = data.FindKeyframe(keyframe);
    if (found == nullptr) return std::nullopt;
    return Seen{found->cam_from_world, found->camera, found->markers};
  });
  if (!seen || seen->markers.empty()) return;
  const std::vector<MarkerId> initialised =
      marker_mapper_->AddKeyframe(keyframe, seen->cam_from_world, seen->camera, seen->markers);
  for (const MarkerId& id : initialised) {
    ARUCOSLAM_LOG_DEBUG("keyframe {}: marker {} mapped", keyframe.value, id.value);
  }
  PublishLocatingMarkers();
}

void System::FeedMarkerView(const Frame& frame) {
  const std::optional<MarkerFix>& fix = marker_fusion_.fix();
  if (!fix || marker_mapping_live_ || !options_.map_unknown_markers ||
      !options_.marker_mapping.marker_views || frame.markers.empty()) {
    return;
  }
  std::vector<MarkerId> initialised;
  const bool taken = EnsureMarkerMapper().AddMarkerView(fix->world_from_cam.Inverse(), frame.camera,
                                                        frame.markers, &initialised);
  if (!taken) return;
  for (const MarkerId& id : initialised) {
    ARUCOSLAM_LOG_DEBUG("frame at t {:.3f}: marker {} mapped from marker views",
                        frame.timestamp_s, id.value);
  }
  // The mapped markers and the views are adjusted together as the views grow by a fifth
  // (and when a marker is mapped), so that frames are located against settled markers.
  const int views = marker_mapper_->NumMarkerViews();
  if (!initialised.empty() || views >= 1.2 * marker_views_refined_ + 1) {
    const MarkerBundleAdjustmentSummary summary = marker_mapper_->RefineMarkers();
    marker_views_refined_ = views;
    ARUCOSLAM_LOG_DEBUG("{} marker views: mapped markers refined: {}", views,
                        summary.BriefReport());
  }
  PublishLocatingMarkers();
}

void System::PublishLocatingMarkers() {
  MarkerMap locating = *options_.marker_map;
  bool any = false;
  for (const auto& [id, landmark] : marker_mapper_->landmarks().landmarks()) {
    if (locating.markers.count(id.value) != 0) continue;
    // A fixed marker the known map lacks is the world origin the mapper adopted.
    const bool locates = landmark.fixed || (options_.min_locating_marker_keyframes > 0 &&
                                            marker_mapper_->NumViews(id) >=
                                                options_.min_locating_marker_keyframes);
    if (!locates) continue;
    locating.markers[id.value] = landmark.ToMarkerInfo();
    any = true;
  }
  if (!any) return;
  auto published = std::make_shared<const MarkerMap>(std::move(locating));
  std::lock_guard lock(locating_mutex_);
  locating_markers_ = std::move(published);
}

std::shared_ptr<const MarkerMap> System::LocatingMarkers() const {
  std::lock_guard lock(locating_mutex_);
  return locating_markers_;  // null until a mapped marker locates: the known map alone
}

int System::ResetMarkerMapping() {
  marker_mapping_live_ = false;
  if (!marker_mapper_) return -1;
  // The markers stay (they are in the world frame); the old map's keyframes are retired at
  // their world poses (their marker views still count in the final refinement).
  return marker_mapper_->CloseMap();
}

void System::AdjustWholeMapWithMarkers(const char* when) {
  if (!marker_mapper_ || !marker_mapping_live_ || !options_.whole_map_marker_adjustment) return;
  // A global BA of the loop closer may be solving: it is discarded, and the landmarks it
  // writes under this lock are not touched meanwhile.
  const std::unique_lock<std::mutex> places_lock = LockPlacesForMapMove();
  const MarkerBundleAdjustmentSummary summary = map_->Write([&](MapData& data) {
    marker_mapper_->SyncKeyframes(data);
    return marker_mapper_->Refine(&data);
  });
  ARUCOSLAM_LOG_DEBUG("bundle adjustment of the whole map with markers ({}, {} views of culled "
                      "keyframes): {}",
                      when, marker_mapper_->NumRetiredViews(), summary.BriefReport());
  if (!summary.success) return;
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_whole_map_marker_adjustments;
}

void System::FinishMarkerMapping() {
  if (!marker_mapper_) return;
  if (marker_mapping_live_ && options_.whole_map_marker_adjustment) {
    AdjustWholeMapWithMarkers("end of the run");
    return;
  }
  map_->Read([&](const MapData& data) {
    marker_mapper_->SyncKeyframes(data);
    return 0;
  });
  int num_mapped = 0;
  for (const auto& [id, landmark] : marker_mapper_->landmarks().landmarks()) {
    if (!landmark.fixed) ++num_mapped;
  }
  if (num_mapped == 0) return;
  const MarkerBundleAdjustmentSummary summary = marker_mapper_->RefineMarkers();
  ARUCOSLAM_LOG_DEBUG("{} mapped markers refined: {}", num_mapped, summary.BriefReport());
}

MarkerMap System::MarkerMapOutput() const {
  if (marker_mapper_) return marker_mapper_->ToMarkerMap();
  return options_.marker_map ? *options_.marker_map : MarkerMap();
}

}  // namespace arucoslam
