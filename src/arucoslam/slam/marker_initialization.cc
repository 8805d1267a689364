#include "arucoslam/slam/marker_initialization.h"

#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/geometry/triangulation.h"
#include "arucoslam/util/logging.h"
#include "arucoslam/util/median.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// The matches of `frame1` in `frame2` triangulated with the known motion: a two-view result
// for CreateInitialMap (cam1 frame, metric), or one with success false when too few points
// are good or their median parallax is below `min_parallax_deg`.
InitializationResult TriangulateWithKnownMotion(const Frame& frame1, const Frame& frame2,
                                                const Rigid3& cam2_from_cam1,
                                                const InitializerOptions& options,
                                                double min_parallax_deg) {
  InitializationResult result;
  const FeatureGrid grid2(frame2.features);
  std::vector<Eigen::Vector2d> predicted;
  predicted.reserve(frame1.features.size());
  for (const cv::KeyPoint& kp : frame1.features.keypoints) predicted.emplace_back(kp.pt.x, kp.pt.y);
  const std::vector<FeatureMatch> matches =
      MatchInWindow(frame1.features, frame2.features, grid2, predicted, options.matching);
  result.num_matches = static_cast<int>(matches.size());
  // The marker poses are a few centimetres off: the gate is wider than the initialiser's,
  // bundle adjustment (CreateInitialMap) refines the motion and drops the outliers.
  const double max_error_sq = std::pow(3.0 * options.max_reprojection_px, 2);
  const Rigid3 identity = Rigid3::Identity();
  std::vector<double> parallaxes;
  for (const FeatureMatch& match : matches) {
    const Eigen::Vector2d& n1 = frame1.features.undistorted[match.index1];
    const Eigen::Vector2d& n2 = frame2.features.undistorted[match.index2];
    const std::optional<Eigen::Vector3d> point = TriangulateDlt(identity, cam2_from_cam1, n1, n2);
    if (!point) continue;
    const TriangulationQuality quality = EvaluateTriangulation(
        *point, identity, cam2_from_cam1, n1, n2, frame1.camera.fx, frame1.camera.fy);
    if (!(quality.depth1 > 0.0) || !(quality.depth2 > 0.0) || quality.error1_sq_px > max_error_sq ||
        quality.error2_sq_px > max_error_sq) {
      continue;
    }
    result.matches.push_back(match);
    result.points_in_cam1.push_back(*point);
    parallaxes.push_back(quality.parallax_rad * 180.0 / std::numbers::pi);
  }
  const int num_points = static_cast<int>(result.matches.size());
  result.median_parallax_deg = Median(parallaxes);
  result.cam2_from_cam1 = cam2_from_cam1;
  result.success =
      num_points >= options.min_triangulated && result.median_parallax_deg >= min_parallax_deg;
  result.message = std::to_string(num_points) + " of " + std::to_string(matches.size()) +
                   " matches triangulated with the marker poses, median parallax " +
                   std::to_string(result.median_parallax_deg) + " deg";
  return result;
}

}  // namespace

bool MarkerInitializationOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("min_baseline_m", min_baseline_m, 0.0);
  check.AtLeast("min_parallax_deg", min_parallax_deg, 0.0);
  check.Nested("alignment", alignment);
  return check.ok();
}

MarkerInitializer::MarkerInitializer(const MarkerInitializationOptions& options,
                                     const InitializerOptions& two_view,
                                     const InitialMapOptions& initial_map)
    : options_(options), two_view_(two_view), initial_map_(initial_map) {}

MarkerInitializationResult MarkerInitializer::Initialize(Map& map, Frame& first, Frame& second,
                                                         const Rigid3& world_from_first,
                                                         const Rigid3& world_from_second,
                                                         std::size_t frame_index) const {
  MarkerInitializationResult result;
  result.baseline_m = (world_from_first.translation - world_from_second.translation).norm();
  if (result.baseline_m < options_.min_baseline_m) {
    result.status = MarkerInitializationStatus::kShortBaseline;
    result.message = "waiting for a marker baseline";  // marker poses are output meanwhile
    return result;
  }
  const InitializationResult triangulated =
      TriangulateWithKnownMotion(first, second, world_from_second.Inverse() * world_from_first,
                                 two_view_, options_.min_parallax_deg);
  ARUCOSLAM_LOG_DEBUG("frame {}: marker initialisation: {}", frame_index, triangulated.message);
  result.message = triangulated.message;
  if (!triangulated.success) return result;
  result.map = CreateInitialMap(map, first, second, triangulated, initial_map_);
  if (!result.map.success) {
    result.message = result.map.message;
    return result;
  }
  // Both marker poses against both keyframes: rotation averaged from the two orientations,
  // scale from the baselines, translation from the centres.
  std::vector<WorldAnchor> anchors(2);
  anchors[0].keyframe = result.map.first;
  anchors[0].cam_from_map = *first.cam_from_world;
  anchors[0].world_from_cam = world_from_first;
  anchors[1].keyframe = result.map.second;
  anchors[1].cam_from_map = *second.cam_from_world;
  anchors[1].world_from_cam = world_from_second;
  const WorldAlignment alignment = EstimateWorldFromMap(anchors, options_.alignment);
  if (!alignment.success) {
    // The map stays (unaligned); world alignment waits for more anchors as usual.
    ARUCOSLAM_LOG_DEBUG("frame {}: marker initialisation not aligned: {}", frame_index,
                        alignment.failure);
    result.status = MarkerInitializationStatus::kUnaligned;
    result.message = alignment.failure;
    return result;
  }
  const Sim3& world_from_map = alignment.world_from_map;
  map.Write([&](MapData& data) { ApplyWorldAlignment(world_from_map, &data); });
  const auto to_world = [&](const Rigid3& cam_from_map) {
    return world_from_map.TransformPose(cam_from_map.Inverse()).Inverse();
  };
  first.cam_from_world = to_world(*first.cam_from_world);
  second.cam_from_world = to_world(*second.cam_from_world);
  result.status = MarkerInitializationStatus::kInWorld;
  result.world_from_map = world_from_map;
  ARUCOSLAM_LOG_DEBUG(
      "frame {}: map initialised from markers in the world, baseline {:.2f} m, "
      "scale {:.3f}",
      frame_index, result.baseline_m, world_from_map.scale);
  return result;
}

}  // namespace arucoslam
