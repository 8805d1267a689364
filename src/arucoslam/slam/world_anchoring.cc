#include "arucoslam/slam/world_anchoring.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "arucoslam/util/logging.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// Largest distance between two anchors' camera centres, metres.
double Baseline(const std::vector<WorldAnchor>& anchors) {
  double baseline = 0.0;
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    for (std::size_t j = i + 1; j < anchors.size(); ++j) {
      baseline = std::max(
          baseline,
          (anchors[i].world_from_cam.translation - anchors[j].world_from_cam.translation).norm());
    }
  }
  return baseline;
}

}  // namespace

bool WorldAnchoringOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("alignment", alignment);
  check.AtLeast("min_alignment_anchors", min_alignment_anchors, 2);
  check.AtLeast("min_alignment_baseline_m", min_alignment_baseline_m, 0.0);
  check.Above("max_alignment_rms_m", max_alignment_rms_m, 0.0);
  check.Above("max_alignment_scale", max_alignment_scale, 0.0);
  check.AtLeast("max_realignment_anchors", max_realignment_anchors, min_alignment_anchors,
                "min_alignment_anchors");
  check.AtLeast("min_marker_correction_m", min_marker_correction_m, 0.0);
  check.AtLeast("marker_correction_sigmas", marker_correction_sigmas, 0.0);
  check.Nested("marker_correction_graph", marker_correction_graph);
  return check.ok();
}

WorldAnchoring::WorldAnchoring(const WorldAnchoringOptions& options) : options_(options) {}

void WorldAnchoring::AddAnchor(KeyframeId keyframe, const std::optional<MarkerFix>& fix) {
  if (!fix || !keyframe.IsValid()) return;
  {
    std::lock_guard lock(fixes_mutex_);
    keyframe_fixes_[keyframe] = *fix;
  }
  if (aligned_ && next_alignment_anchors_ > options_.max_realignment_anchors) return;
  anchors_.push_back({keyframe, fix->world_from_cam});
}

std::optional<AlignmentDecision> WorldAnchoring::DecideAlignment(const Map& map) {
  const int needed = std::max(options_.min_alignment_anchors, next_alignment_anchors_);
  if (static_cast<int>(anchors_.size()) < needed) return std::nullopt;
  AlignmentDecision decision;
  std::vector<WorldAnchor>& anchors = decision.anchors;
  std::vector<MarkerAnchor> live;  // anchors whose keyframe is still in the map
  map.Read([&](const MapData& data) {
    for (const MarkerAnchor& anchor : anchors_) {
      const Keyframe* keyframe = data.FindKeyframe(anchor.keyframe);
      if (keyframe == nullptr) continue;
      live.push_back(anchor);
      WorldAnchor world_anchor;
      world_anchor.keyframe = anchor.keyframe;
      world_anchor.cam_from_map = keyframe->cam_from_world;
      world_anchor.world_from_cam = anchor.world_from_cam;
      anchors.push_back(world_anchor);
    }
    return 0;
  });
  anchors_ = std::move(live);
  const double baseline_m = Baseline(anchors);
  if (static_cast<int>(anchors.size()) < needed || baseline_m < options_.min_alignment_baseline_m) {
    ARUCOSLAM_LOG_DEBUG(
        "world alignment waits: {} anchors with keyframes ({} needed), baseline {:.2f} m",
        anchors.size(), needed, baseline_m);
    return std::nullopt;
  }
  decision.alignment = EstimateWorldFromMap(anchors, options_.alignment);
  const WorldAlignment& alignment = decision.alignment;
  if (!alignment.success || alignment.rms_m > options_.max_alignment_rms_m ||
      (!aligned_ && alignment.world_from_map.scale > options_.max_alignment_scale)) {
    ARUCOSLAM_LOG_DEBUG("world alignment refused ({} anchors): {} rms {:.3f} m, scale {:.2f}",
                        anchors.size(), alignment.failure, alignment.rms_m,
                        alignment.world_from_map.scale);
    return std::nullopt;
  }
  return decision;
}

void WorldAnchoring::DropOutlierFixes(const AlignmentDecision& decision) {
  // An anchor the alignment found an outlier has a wrong marker location (a mirrored
  // one-marker solution, a far marker): no drift correction may pull the map towards it.
  std::lock_guard lock(fixes_mutex_);
  for (std::size_t i = 0; i < decision.anchors.size(); ++i) {
    if (!decision.alignment.inliers[i]) keyframe_fixes_.erase(decision.anchors[i].keyframe);
  }
}

void WorldAnchoring::AlignmentApplied(const AlignmentDecision& decision) {
  next_alignment_anchors_ = 2 * static_cast<int>(decision.anchors.size());
  aligned_ = true;
  ++num_alignments_;
}

void WorldAnchoring::AlignedFromMarkers() {
  aligned_ = true;
  next_alignment_anchors_ = options_.min_alignment_anchors;
  ++num_alignments_;
}

WorldAnchoringStats WorldAnchoring::stats() const {
  WorldAnchoringStats stats;
  stats.num_alignments = num_alignments_;
  stats.num_drift_corrections = num_drift_corrections_;
  return stats;
}

void WorldAnchoring::StopRealigning() {
  next_alignment_anchors_ = options_.max_realignment_anchors + 1;
  anchors_.clear();
}

void WorldAnchoring::StartLoadedMap(bool aligned) {
  aligned_ = aligned;
  // An aligned map is not aligned again (AddAnchor stops collecting anchors).
  if (aligned) next_alignment_anchors_ = options_.max_realignment_anchors + 1;
}

void WorldAnchoring::Reset() {
  anchors_.clear();
  {
    std::lock_guard lock(fixes_mutex_);
    keyframe_fixes_.clear();
  }
  next_alignment_anchors_ = 0;
  aligned_ = false;
}

std::map<KeyframeId, MarkerFix> WorldAnchoring::KeyframeFixes() const {
  std::lock_guard lock(fixes_mutex_);
  return keyframe_fixes_;
}

void WorldAnchoring::AddKeyframeFixes(const std::map<KeyframeId, MarkerFix>& fixes) {
  std::lock_guard lock(fixes_mutex_);
  for (const auto& [id, fix] : fixes) keyframe_fixes_[id] = fix;
}

}  // namespace arucoslam
