#include "arucoslam/slam/marker_fusion.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "arucoslam/optim/marker_corner_error.h"
#include "arucoslam/optim/marker_location_information.h"
#include "arucoslam/util/logging.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// Distance from the camera at `world_from_cam` to its nearest located marker, in that
// marker's sides.
double NearestMarkerInSides(const CameraLocation& location, const Rigid3& world_from_cam,
                            const MarkerMap& map) {
  double nearest = std::numeric_limits<double>::infinity();
  for (const int id : location.marker_ids) {
    const MarkerInfo* info = map.Find(id);
    const double distance =
        (info->world_from_marker.translation - world_from_cam.translation).norm();
    nearest = std::min(nearest, distance / info->size);
  }
  return nearest;
}

// For the logs: how far both solutions of an ambiguous location lie from a prediction.
std::string DistancesFrom(const CameraLocation& location, const Rigid3& predicted) {
  const auto describe = [&predicted](const Rigid3& pose) {
    return fmt::format("{:.1f} deg {:.2f} m",
                       RotationAngle(pose.rotation.inverse() * predicted.rotation) * 180.0 / M_PI,
                       (pose.translation - predicted.translation).norm());
  };
  return "best " + describe(location.world_from_cam) + ", other " +
         describe(*location.alternative_world_from_cam);
}

// The same for an orientation alone (the map's voted world rotation).
std::string AnglesFrom(const CameraLocation& location, const Eigen::Quaterniond& world_from_cam) {
  const auto describe = [&world_from_cam](const Rigid3& pose) {
    return fmt::format("{:.1f} deg",
                       RotationAngle(pose.rotation.inverse() * world_from_cam) * 180.0 / M_PI);
  };
  return "best " + describe(location.world_from_cam) + ", other " +
         describe(*location.alternative_world_from_cam);
}

// The detections of markers absent from the locating map.
std::vector<MarkerDetection> UnknownDetections(const CameraLocation& location,
                                               const std::vector<MarkerDetection>& detections) {
  std::vector<MarkerDetection> unknown;
  for (const MarkerDetection& detection : detections) {
    if (std::binary_search(location.unknown_marker_ids.begin(), location.unknown_marker_ids.end(),
                           detection.id)) {
      unknown.push_back(detection);
    }
  }
  return unknown;
}

}  // namespace

bool MarkerFusionOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("locator", locator);
  check.Above("max_marker_rms_px", max_marker_rms_px, 0.0);
  check.Above("max_marker_distance_sides", max_marker_distance_sides, 0.0);
  check.Nested("ambiguity_gates", ambiguity_gates);
  check.Nested("fix_motion", fix_motion);
  check.Nested("rotation_vote", rotation_vote);
  check.Nested("map_rotation_gates", map_rotation_gates);
  check.Nested("covisible_vote", covisible_vote);
  check.Above("max_marker_disagreement_m", max_marker_disagreement_m, 0.0);
  return check.ok();
}

MarkerFusion::MarkerFusion(const MarkerFusionOptions& options, const CameraModel& camera,
                           const MarkerMap& known, double unknown_marker_size_m)
    : options_(options),
      camera_(camera),
      unknown_marker_size_m_(unknown_marker_size_m),
      fix_motion_(options.fix_motion),
      rotation_vote_(options.rotation_vote),
      covisible_vote_(options.covisible_vote) {
  for (const auto& [id, info] : known.markers) {
    if (info.fixed) fixed_marker_ids_.push_back(id);
  }
}

const std::optional<MarkerFix>& MarkerFusion::Locate(const std::vector<MarkerDetection>& detections,
                                                     const MarkerMap& locating, double timestamp_s,
                                                     const MapPrediction& map,
                                                     std::size_t frame_index) {
  const CameraLocation location = LocateCamera(detections, locating, camera_, options_.locator);
  num_markers_ = static_cast<int>(location.marker_ids.size());
  fix_.reset();
  const bool ambiguous = location.found && location.quality.ambiguous;
  // An ambiguous location counts only as the solution a prediction or vote settles on.
  bool by_map_rotation = false, by_covisible = false;
  AmbiguityChoice choice = ambiguous && options_.resolve_ambiguity_by_motion
                               ? ResolveByMotion(location, timestamp_s, map, &by_map_rotation)
                               : AmbiguityChoice::kNone;
  if (choice == AmbiguityChoice::kNone && ambiguous &&
      options_.resolve_ambiguity_by_covisible_markers) {
    choice = covisible_vote_.Add(location, UnknownDetections(location, detections),
                                 unknown_marker_size_m_, camera_);
    by_covisible = choice != AmbiguityChoice::kNone;
  }
  ambiguous_location_.reset();
  const bool resolved = choice != AmbiguityChoice::kNone;
  const bool alternative = choice == AmbiguityChoice::kAlternative;
  double nearest_sides = std::numeric_limits<double>::infinity();
  const bool usable =
      location.found && UsableLocation(location, alternative, locating, &nearest_sides);
  if (ambiguous && location.alternative_world_from_cam && usable && !map.world_aligned &&
      options_.resolve_ambiguity_by_map_rotation) {
    ambiguous_location_ = location;  // votes for the map's orientation once tracked
  }
  if (!location.found || (ambiguous && !resolved) || !usable) return fix_;
  const Rigid3 world_from_cam = resolved ? *ChosenPose(location, choice) : location.world_from_cam;
  fix_ = MakeFix(location, world_from_cam, detections, locating);
  fix_->settled_ambiguity = resolved;
  fix_motion_.Add(timestamp_s, fix_->world_from_cam);
  ++stats_.num_located_frames;
  if (resolved) {
    ++stats_.num_disambiguations;
    if (by_map_rotation) ++stats_.num_map_rotation_disambiguations;
    if (by_covisible) ++stats_.num_covisible_disambiguations;
    ARUCOSLAM_LOG_DEBUG("frame {}: ambiguous marker {} settled by the motion prediction{}",
                        frame_index, location.marker_ids.front(),
                        alternative ? " (IPPE's second solution)" : "");
  }
  return fix_;
}

MarkerFix MarkerFusion::MakeFix(const CameraLocation& location, const Rigid3& world_from_cam,
                                const std::vector<MarkerDetection>& detections,
                                const MarkerMap& locating) const {
  MarkerFix fix;
  fix.world_from_cam = world_from_cam;
  fix.known_markers_only =
      std::all_of(location.marker_ids.begin(), location.marker_ids.end(), [&](int id) {
        return std::binary_search(fixed_marker_ids_.begin(), fixed_marker_ids_.end(), id);
      });
  for (const MarkerDetection& detection : detections) {
    if (!std::binary_search(location.marker_ids.begin(), location.marker_ids.end(), detection.id)) {
      continue;
    }
    const MarkerInfo* info = locating.Find(detection.id);
    MarkerPoseObservation observation;
    observation.world_from_marker = info->world_from_marker;
    observation.size = info->size;
    observation.corners_px = UndistortedCorners(camera_, detection.corners);
    fix.markers.push_back(observation);
  }
  fix.corner_information = MarkerLocationInformation(world_from_cam, fix.markers,
                                                     PinholeIntrinsics::FromCamera(camera_));
  return fix;
}

bool MarkerFusion::UsableLocation(const CameraLocation& location, bool alternative,
                                  const MarkerMap& map, double* nearest_sides) const {
  const double rms_px =
      alternative ? location.quality.alternative_rms_px : location.quality.reprojection_rms_px;
  const Rigid3& world_from_cam =
      alternative ? *location.alternative_world_from_cam : location.world_from_cam;
  *nearest_sides = NearestMarkerInSides(location, world_from_cam, map);
  return rms_px <= options_.max_marker_rms_px &&
         *nearest_sides <= options_.max_marker_distance_sides;
}

AmbiguityChoice MarkerFusion::ResolveByMotion(const CameraLocation& location, double timestamp_s,
                                              const MapPrediction& map,
                                              bool* by_map_rotation) const {
  // The map's motion model (keypoint poses in the world; before the alignment, orientations
  // through the voted world rotation) and the recent marker fixes predict independently;
  // when both settle the ambiguity they must agree.
  *by_map_rotation = false;
  if (!location.alternative_world_from_cam) return AmbiguityChoice::kNone;
  AmbiguityChoice by_tracker = AmbiguityChoice::kNone;
  bool tracker_prediction = false, fixes_prediction = false, map_rotation_prediction = false;
  if (map.world_aligned) {
    if (map.predicted_cam_from_map) {
      const Rigid3 predicted = map.predicted_cam_from_map->Inverse();
      tracker_prediction = true;
      by_tracker = ResolveAmbiguity(location, predicted, options_.ambiguity_gates);
      ARUCOSLAM_LOG_DEBUG("t {:.3f}: ambiguous marker vs tracker prediction: {}", timestamp_s,
                          DistancesFrom(location, predicted));
    }
  } else if (options_.resolve_ambiguity_by_map_rotation && rotation_vote_.WorldFromMap() &&
             map.tracking && map.predicted_cam_from_map) {
    tracker_prediction = map_rotation_prediction = true;
    const Eigen::Quaterniond world_from_cam =
        *rotation_vote_.WorldFromMap() * map.predicted_cam_from_map->rotation.inverse();
    by_tracker = ResolveAmbiguityByRotation(location, world_from_cam, options_.map_rotation_gates);
    ARUCOSLAM_LOG_DEBUG("t {:.3f}: ambiguous marker vs the map's voted orientation: {}",
                        timestamp_s, AnglesFrom(location, world_from_cam));
  }
  AmbiguityChoice by_fixes = AmbiguityChoice::kNone;
  if (const std::optional<Rigid3> predicted = fix_motion_.Predict(timestamp_s)) {
    fixes_prediction = true;
    by_fixes = ResolveAmbiguity(location, *predicted, options_.ambiguity_gates);
    ARUCOSLAM_LOG_DEBUG("t {:.3f}: ambiguous marker vs marker-fix prediction: {}", timestamp_s,
                        DistancesFrom(location, *predicted));
  }
  if (!tracker_prediction && !fixes_prediction) {
    ARUCOSLAM_LOG_DEBUG("t {:.3f}: ambiguous marker, no motion prediction", timestamp_s);
  }
  if (by_tracker == AmbiguityChoice::kNone) return by_fixes;
  if (by_fixes != AmbiguityChoice::kNone && by_fixes != by_tracker) return AmbiguityChoice::kNone;
  // Counted as the map rotation's only when the fixes did not settle it too.
  *by_map_rotation = map_rotation_prediction && by_fixes == AmbiguityChoice::kNone;
  return by_tracker;
}

std::optional<Rigid3> MarkerFusion::LocateInMap(
    const std::vector<MarkerObservation>& markers, const MarkerMap& map,
    const std::optional<Rigid3>& previous_cam_from_world) const {
  std::vector<MarkerDetection> detections;
  for (const MarkerObservation& observation : markers) {
    detections.push_back(observation.AsDetection());
  }
  const CameraLocation location = LocateCamera(detections, map, camera_, options_.locator);
  if (!location.found) return std::nullopt;
  AmbiguityChoice choice = AmbiguityChoice::kBest;
  if (location.quality.ambiguous) {
    choice = previous_cam_from_world
                 ? ResolveAmbiguity(location, previous_cam_from_world->Inverse(),
                                    options_.ambiguity_gates)
                 : AmbiguityChoice::kNone;
  }
  if (choice == AmbiguityChoice::kNone) return std::nullopt;
  double nearest_sides = 0.0;
  if (!UsableLocation(location, choice == AmbiguityChoice::kAlternative, map, &nearest_sides)) {
    return std::nullopt;
  }
  return ChosenPose(location, choice)->Inverse();
}

}  // namespace arucoslam
