#include "arucoslam/slam/local_mapper.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "arucoslam/util/logging.h"
#include "arucoslam/util/option_check.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

bool LocalMapperOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("triangulation_neighbours", triangulation_neighbours, 0);
  check.AtLeast("min_baseline_depth_ratio", min_baseline_depth_ratio, 0.0);
  check.AtLeast("max_match_distance", max_match_distance, 0);
  check.InRange("match_ratio", match_ratio, 0.0, 1.0, Interval::kOpenClosed);
  check.Above("epipolar_chi2", epipolar_chi2, 0.0);
  check.AtLeast("min_epipole_distance_px", min_epipole_distance_px, 0.0);
  check.InRange("max_parallax_cos", max_parallax_cos, 0.0, 1.0, Interval::kOpen);
  check.Above("reprojection_chi2", reprojection_chi2, 0.0);
  check.AtLeast("scale_consistency_factor", scale_consistency_factor, 1.0);
  check.AtLeast("fusion_neighbours", fusion_neighbours, 0);
  check.Above("fusion_radius_px", fusion_radius_px, 0.0);
  check.AtLeast("fusion_max_distance", fusion_max_distance, 0);
  check.InRange("min_found_ratio", min_found_ratio, 0.0, 1.0, Interval::kClosed);
  check.AtLeast("min_point_observations", min_point_observations, 1);
  check.Nested("bundle_adjustment", bundle_adjustment);
  check.InRange("redundant_fraction", redundant_fraction, 0.0, 1.0, Interval::kOpenClosed);
  check.AtLeast("redundant_observers", redundant_observers, 1);
  check.AtLeast("min_marker_keyframes", min_marker_keyframes, 0);
  check.AtLeast("min_keyframe_points", min_keyframe_points, 0);
  return check.ok();
}

LocalMapper::LocalMapper(Map& map, const LocalMapperOptions& options)
    : map_(map), options_(options) {}

LocalMappingResult LocalMapper::ProcessKeyframe(KeyframeId keyframe) {
  LocalMappingResult result;
  const bool exists =
      map_.Read([&](const MapData& data) { return data.FindKeyframe(keyframe) != nullptr; });
  if (!exists) return result;
  ++num_processed_;
  result.processed = true;
  Stopwatch watch;
  result.num_refreshed_points = RefreshKeyframePoints(keyframe);
  result.num_culled_points = CullRecentPoints();
  result.culling_ms = watch.ElapsedMilliseconds();
  watch.Restart();
  result.num_new_points = TriangulateNewPoints(keyframe);
  result.triangulation_ms = watch.ElapsedMilliseconds();
  watch.Restart();
  result.num_fused_points = FuseDuplicates(keyframe);
  result.fusion_ms = watch.ElapsedMilliseconds();
  watch.Restart();
  if (options_.run_bundle_adjustment && map_.NumKeyframes() > 2) {
    result.bundle_adjustment =
        RunLocalBundleAdjustment(map_, keyframe, options_.bundle_adjustment, markers_);
  }
  result.bundle_adjustment_ms = watch.ElapsedMilliseconds();
  watch.Restart();
  if (options_.cull_keyframes) result.num_culled_keyframes = CullRedundantKeyframes(keyframe);
  result.culling_ms += watch.ElapsedMilliseconds();
  return result;
}

int LocalMapper::RefreshKeyframePoints(KeyframeId keyframe) {
  return map_.Write([&](MapData& data) {
    const std::vector<MapPointId> points = data.MapPointsOf(keyframe);
    for (const MapPointId& id : points) {
      data.UpdateNormalAndDepth(id);
      data.UpdateDescriptor(id);
    }
    return static_cast<int>(points.size());
  });
}

int LocalMapper::CullRecentPoints() {
  return map_.Write([&](MapData& data) {
    int culled = 0;
    std::vector<std::pair<MapPointId, int>> kept;
    for (const auto& [id, created] : recent_points_) {
      const MapPoint* point = data.FindMapPoint(id);
      if (point == nullptr) continue;
      const int age = num_processed_ - created;
      if (point->FoundRatio() < options_.min_found_ratio ||
          (age >= 2 && point->NumObservations() < options_.min_point_observations)) {
        data.EraseMapPoint(id);
        ++culled;
      } else if (age < 3) {
        kept.emplace_back(id, created);
      }
    }
    recent_points_ = std::move(kept);
    return culled;
  });
}

namespace {

// Whether `candidate` has more than `fraction` of its points seen by at least `observers`
// other keyframes at the same or a finer scale (level at most one above). Stops counting as
// soon as the answer is settled either way.
bool IsRedundant(const MapData& data, const Keyframe& candidate, double fraction,
                 int observers) {
  std::vector<std::pair<const MapPoint*, int>> points;  // with the candidate's keypoint level
  for (std::size_t i = 0; i < candidate.map_point_ids.size(); ++i) {
    if (const MapPoint* point = data.FindMapPoint(candidate.map_point_ids[i])) {
      points.emplace_back(point, candidate.features.keypoints[i].octave);
    }
  }
  const int num_points = static_cast<int>(points.size());
  const double needed = fraction * num_points;  // redundant points must exceed this
  int num_redundant = 0;
  for (int k = 0; k < num_points; ++k) {
    if (num_redundant > needed) return true;
    if (num_redundant + (num_points - k) <= needed) return false;
    const auto& [point, level] = points[k];
    if (point->NumObservations() <= observers) continue;
    int count = 0;
    for (const auto& [other, index] : point->observations) {
      if (other == candidate.id) continue;
      if (data.FindKeyframe(other)->features.keypoints[index].octave <= level + 1) ++count;
    }
    if (count >= observers) ++num_redundant;
  }
  return num_points > 0 && num_redundant > needed;
}

// Whether `keyframe` observes fewer than `n` map points (stops counting at n).
bool HasFewerMapPoints(const Keyframe& keyframe, int n) {
  int count = 0;
  for (const MapPointId& id : keyframe.map_point_ids) {
    if (id.IsValid() && ++count >= n) return false;
  }
  return count < n;
}

int NumMapPoints(const Keyframe& keyframe) {
  return static_cast<int>(std::count_if(keyframe.map_point_ids.begin(),
                                        keyframe.map_point_ids.end(),
                                        [](const MapPointId& id) { return id.IsValid(); }));
}

// Whether `candidate` saw a marker of `markers` that fewer than `min_others` other
// keyframes saw.
bool HoldsRareMarkerView(const Keyframe& candidate, const MarkerLandmarks* markers,
                         int min_others) {
  if (markers == nullptr) return false;
  for (const MarkerObservation& observation : candidate.markers) {
    const MarkerLandmark* landmark = markers->Find(observation.marker_id);
    if (landmark == nullptr || landmark->observations.count(candidate.id) == 0) continue;
    if (static_cast<int>(landmark->observations.size()) - 1 < min_others) return true;
  }
  return false;
}

}  // namespace

int LocalMapper::CullRedundantKeyframes(KeyframeId keyframe) {
  // One keyframe at a time: each erasure changes what the next candidates share.
  return map_.Write([&](MapData& data) {
    if (data.FindKeyframe(keyframe) == nullptr) return 0;
    // Only older keyframes: newer ones may still wait in the mapper's queue.
    const auto older = [&](KeyframeId id) { return id != data.FirstKeyframe() && id < keyframe; };
    std::vector<KeyframeId> candidates;
    for (const auto& [candidate, weight] : data.covisibility().Neighbours(keyframe)) {
      if (older(candidate)) candidates.push_back(candidate);
    }
    // Keyframes that lost their points need not be covisible with anything any more.
    for (const auto& [id, candidate] : data.keyframes()) {
      if (older(id) && HasFewerMapPoints(candidate, options_.min_keyframe_points) &&
          std::find(candidates.begin(), candidates.end(), id) == candidates.end()) {
        candidates.push_back(id);
      }
    }
    int erased = 0;
    for (const KeyframeId& id : candidates) {
      const Keyframe* candidate = data.FindKeyframe(id);
      if (candidate == nullptr || (keep_ && keep_(*candidate)) ||
          HoldsRareMarkerView(*candidate, markers_, options_.min_marker_keyframes)) {
        continue;
      }
      const bool lost_its_points = HasFewerMapPoints(*candidate, options_.min_keyframe_points);
      if (!lost_its_points && !IsRedundant(data, *candidate, options_.redundant_fraction,
                                           options_.redundant_observers)) {
        continue;
      }
      if (lost_its_points) {
        ARUCOSLAM_LOG_DEBUG("keyframe {} erased: {} map points left", id.value,
                            NumMapPoints(*candidate));
      }
      if (!data.EraseKeyframe(id)) continue;
      ++erased;
      if (markers_ != nullptr) markers_->EraseKeyframe(id);
    }
    return erased;
  });
}

}  // namespace arucoslam
