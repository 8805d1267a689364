#include "arucoslam/slam/online_marker_mapping.h"

#include <utility>

#include "arucoslam/util/logging.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool OnlineMarkerMappingOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("mapper", mapper);
  check.AtLeast("min_locating_keyframes", min_locating_keyframes, 0);
  return check.ok();
}

OnlineMarkerMapping::OnlineMarkerMapping(std::optional<MarkerMap> known,
                                         const OnlineMarkerMappingOptions& options)
    : known_(std::move(known)), options_(options) {
  if (known_) locating_markers_ = std::make_shared<const MarkerMap>(*known_);
}

MarkerMapper& OnlineMarkerMapping::EnsureMapper() {
  if (!mapper_) {
    MarkerMapperOptions mapping = options_.mapper;
    mapping.map_unknown = mapping.map_unknown && options_.map_unknown_markers;
    mapper_ = std::make_unique<MarkerMapper>(*known_, mapping);
  }
  return *mapper_;
}

void OnlineMarkerMapping::AdoptWorldOrigin(const std::vector<MarkerDetection>& detections,
                                           const CameraModel& camera) {
  if (known_ && known_->markers.empty() && !detections.empty() && !live_ &&
      EnsureMapper().AdoptWorldOrigin(detections, camera)) {
    PublishLocatingMarkers();
  }
}

void OnlineMarkerMapping::AddMarkerView(const Frame& frame, const std::optional<MarkerFix>& fix) {
  if (!known_ || !fix || live_ || !options_.map_unknown_markers || !options_.mapper.marker_views ||
      frame.markers.empty()) {
    return;
  }
  std::vector<MarkerId> initialised;
  const bool taken = EnsureMapper().AddMarkerView(fix->world_from_cam.Inverse(), frame.camera,
                                                  frame.markers, &initialised);
  if (!taken) return;
  for (const MarkerId& id : initialised) {
    ARUCOSLAM_LOG_DEBUG("frame at t {:.3f}: marker {} mapped from marker views", frame.timestamp_s,
                        id.value);
  }
  // The mapped markers and the views are adjusted together as the views grow by a fifth
  // (and when a marker is mapped), so that frames are located against settled markers.
  const int views = mapper_->NumMarkerViews();
  if (!initialised.empty() || views >= 1.2 * marker_views_refined_ + 1) {
    const MarkerBundleAdjustmentSummary summary = mapper_->RefineMarkers();
    marker_views_refined_ = views;
    ARUCOSLAM_LOG_DEBUG("{} marker views: mapped markers refined: {}", views,
                        summary.BriefReport());
  }
  PublishLocatingMarkers();
}

bool OnlineMarkerMapping::Start() {
  if (!known_) return false;
  EnsureMapper();
  live_ = true;
  return true;
}

MarkerLandmarks* OnlineMarkerMapping::landmarks_for_bundle_adjustment() {
  return options_.markers_in_local_ba ? live_landmarks() : nullptr;
}

MarkerLandmarks* OnlineMarkerMapping::live_landmarks() {
  return live_ ? mapper_->mutable_landmarks() : nullptr;
}

std::vector<KeyframeId> OnlineMarkerMapping::UnfedKeyframes(const Map& map) const {
  if (!mapper_) return {};
  return map.Read([&](const MapData& data) {
    std::vector<KeyframeId> ids;
    for (const auto& [id, keyframe] : data.keyframes()) {
      if (!mapper_->Records(id)) ids.push_back(id);
    }
    return ids;
  });
}

void OnlineMarkerMapping::AddKeyframe(const Map& map, KeyframeId keyframe) {
  if (!live_) return;
  struct Seen {
    Rigid3 cam_from_world;
    CameraModel camera;
    std::vector<MarkerObservation> markers;
  };
  const std::optional<Seen> seen = map.Read([&](const MapData& data) -> std::optional<Seen> {
    mapper_->SyncKeyframes(data);
    const Keyframe* found = data.FindKeyframe(keyframe);
    if (found == nullptr) return std::nullopt;
    return Seen{found->cam_from_world, found->camera, found->markers};
  });
  if (!seen || seen->markers.empty()) return;
  const std::vector<MarkerId> initialised =
      mapper_->AddKeyframe(keyframe, seen->cam_from_world, seen->camera, seen->markers);
  for (const MarkerId& id : initialised) {
    ARUCOSLAM_LOG_DEBUG("keyframe {}: marker {} mapped", keyframe.value, id.value);
  }
  PublishLocatingMarkers();
}

void OnlineMarkerMapping::ApplySimilarity(const Sim3& new_from_old,
                                          const std::set<KeyframeId>* stay) {
  if (live_) mapper_->ApplySimilarity(new_from_old, stay);
}

int OnlineMarkerMapping::CloseMap() {
  live_ = false;
  if (!mapper_) return -1;
  // The markers stay (they are in the world frame); the old map's keyframes are retired at
  // their world poses (their marker views still count in the final refinement).
  return mapper_->CloseMap();
}

int OnlineMarkerMapping::ReviveClosedMap(int generation,
                                         const std::map<KeyframeId, KeyframeId>& new_ids) {
  if (!mapper_ || generation < 0) return 0;
  return mapper_->ReviveClosedMap(generation, new_ids);
}

void OnlineMarkerMapping::SetPositionPriors(const std::vector<KeyframePosePrior>& priors) {
  if (mapper_) mapper_->SetPositionPriors(priors);
}

std::optional<DriftCorrectionDecision> OnlineMarkerMapping::DecideDriftCorrection(
    const Map& map, const WorldAnchoring& anchoring, KeyframeId keyframe) const {
  if (!live_) return std::nullopt;
  return anchoring.DecideDriftCorrection(map, keyframe);
}

EssentialGraphResult OnlineMarkerMapping::CorrectDrift(Map* map, KeyframeId keyframe,
                                                       const DriftCorrectionDecision& decision,
                                                       const EssentialGraphOptions& graph) const {
  const EssentialGraphResult result =
      OptimizeEssentialGraph(*map, KeyframeId(), {}, {}, decision.priors, graph);
  ARUCOSLAM_LOG_DEBUG(
      "keyframe {}: {:.3f} m from its markers ({:.1f} sigmas), map corrected "
      "over {} keyframes with {} marker priors: {}",
      keyframe.value, decision.offset_m, decision.offset_sigmas, result.num_keyframes,
      result.num_priors, result.summary.BriefReport());
  return result;
}

bool OnlineMarkerMapping::AdjustsWholeMap() const {
  return mapper_ && live_ && options_.whole_map_adjustment;
}

bool OnlineMarkerMapping::AdjustWholeMap(Map* map, const char* when) {
  const MarkerBundleAdjustmentSummary summary = map->Write([&](MapData& data) {
    mapper_->SyncKeyframes(data);
    return mapper_->Refine(&data);
  });
  ARUCOSLAM_LOG_DEBUG(
      "bundle adjustment of the whole map with markers ({}, {} views of culled "
      "keyframes): {}",
      when, mapper_->NumRetiredViews(), summary.BriefReport());
  if (summary.success) ++stats_.num_whole_map_adjustments;
  return summary.success;
}

void OnlineMarkerMapping::RefineMappedMarkers(const Map& map) {
  if (!mapper_) return;
  map.Read([&](const MapData& data) {
    mapper_->SyncKeyframes(data);
    return 0;
  });
  int num_mapped = 0;
  for (const auto& [id, landmark] : mapper_->landmarks().landmarks()) {
    if (!landmark.fixed) ++num_mapped;
  }
  if (num_mapped == 0) return;
  const MarkerBundleAdjustmentSummary summary = mapper_->RefineMarkers();
  ARUCOSLAM_LOG_DEBUG("{} mapped markers refined: {}", num_mapped, summary.BriefReport());
}

void OnlineMarkerMapping::PublishLocatingMarkers() {
  MarkerMap locating = *known_;
  bool any = false;
  for (const auto& [id, landmark] : mapper_->landmarks().landmarks()) {
    if (locating.markers.count(id.value) != 0) continue;
    // A fixed marker the known map lacks is the world origin the mapper adopted.
    const bool locates =
        landmark.fixed || (options_.min_locating_keyframes > 0 &&
                           mapper_->NumViews(id) >= options_.min_locating_keyframes);
    if (!locates) continue;
    locating.markers[id.value] = landmark.ToMarkerInfo();
    any = true;
  }
  if (!any) return;
  auto published = std::make_shared<const MarkerMap>(std::move(locating));
  std::lock_guard lock(locating_mutex_);
  locating_markers_ = std::move(published);
}

std::shared_ptr<const MarkerMap> OnlineMarkerMapping::LocatingMarkers() const {
  std::lock_guard lock(locating_mutex_);
  return locating_markers_;
}

MarkerMap OnlineMarkerMapping::ToMarkerMap() const {
  if (mapper_) return mapper_->ToMarkerMap();
  return known_ ? *known_ : MarkerMap();
}

}  // namespace arucoslam
