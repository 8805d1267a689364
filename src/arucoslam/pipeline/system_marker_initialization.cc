// System's map initialisation from two marker locations: the matches triangulated with the
// markers' relative pose, the map built directly in the marker world.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/geometry/triangulation.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/slam/map_initialization.h"
#include "arucoslam/util/logging.h"
#include "arucoslam/util/median.h"

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
    if (!(quality.depth1 > 0.0) || !(quality.depth2 > 0.0) ||
        quality.error1_sq_px > max_error_sq || quality.error2_sq_px > max_error_sq) {
      continue;
    }
    result.matches.push_back(match);
    result.points_in_cam1.push_back(*point);
    parallaxes.push_back(quality.parallax_rad * 180.0 / std::numbers::pi);
  }
  const int num_points = static_cast<int>(result.matches.size());
  result.median_parallax_deg = Median(parallaxes);
  result.cam2_from_cam1 = cam2_from_cam1;
  result.success = num_points >= options.min_triangulated &&
                   result.median_parallax_deg >= min_parallax_deg;
  result.message = std::to_string(num_points) + " of " + std::to_string(matches.size()) +
                   " matches triangulated with the marker poses, median parallax " +
                   std::to_string(result.median_parallax_deg) + " deg";
  return result;
}

}  // namespace

bool System::InitializeFromMarkers(Frame& frame, FrameReport& report) {
  const std::optional<MarkerFix>& fix = marker_fusion_.fix();
  if (!fix) return false;
  if (!init_reference_fix_) {
    // A reference with a marker location allows the metric initialisation below.
    if (report.num_features >= options_.initializer.min_matches) {
      ReplaceInitReference(frame);
      report.message = "initialisation reference (markers)";
      return true;
    }
    return false;
  }
  const Rigid3& world_from_cam1 = init_reference_fix_->world_from_cam;
  const Rigid3& world_from_cam2 = fix->world_from_cam;
  const double baseline = (world_from_cam1.translation - world_from_cam2.translation).norm();
  if (baseline < options_.min_marker_init_baseline_m) {
    report.message = "waiting for a marker baseline";  // marker poses are output meanwhile
    return true;
  }
  Frame first = *init_reference_;
  const InitializationResult triangulated =
      TriangulateWithKnownMotion(first, frame, world_from_cam2.Inverse() * world_from_cam1,
                                 options_.initializer, options_.min_marker_init_parallax_deg);
  ARUCOSLAM_LOG_DEBUG("frame {}: marker initialisation: {}", report.index, triangulated.message);
  if (!triangulated.success) return false;
  const InitialMapResult created =
      CreateInitialMap(*map_, first, frame, triangulated, options_.initial_map);
  if (!created.success) {
    report.message = created.message;
    return false;
  }
  // Both marker poses against both keyframes: rotation averaged from the two orientations,
  // scale from the baselines, translation from the centres.
  std::vector<WorldAnchor> anchors(2);
  anchors[0].keyframe = created.first;
  anchors[0].cam_from_map = *first.cam_from_world;
  anchors[0].world_from_cam = world_from_cam1;
  anchors[1].keyframe = created.second;
  anchors[1].cam_from_map = *frame.cam_from_world;
  anchors[1].world_from_cam = world_from_cam2;
  const WorldAlignment alignment =
      EstimateWorldFromMap(anchors, options_.world_anchoring.alignment);
  if (!alignment.success) {
    // The map stays (unaligned); world alignment waits for more anchors as usual.
    ARUCOSLAM_LOG_DEBUG("frame {}: marker initialisation not aligned: {}", report.index,
                        alignment.failure);
    FinishInitialization(first, frame, created.first, created.second, created.num_points, report);
    return true;
  }
  const Sim3& world_from_map = alignment.world_from_map;
  map_->Write([&](MapData& data) { ApplyWorldAlignment(world_from_map, &data); });
  const auto to_world = [&](const Rigid3& cam_from_map) {
    return world_from_map.TransformPose(cam_from_map.Inverse()).Inverse();
  };
  first.cam_from_world = to_world(*first.cam_from_world);
  frame.cam_from_world = to_world(*frame.cam_from_world);
  anchoring_.AlignedFromMarkers();  // re-aligned as anchors come
  marker_fusion_.MapEnteredWorld(frame.timestamp_s);
  RefreshKeyframePoseCache();
  {
    std::lock_guard lock(stats_mutex_);
    ++stats_.num_marker_initializations;
  }
  ARUCOSLAM_LOG_DEBUG("frame {}: map initialised from markers in the world, baseline {:.2f} m, "
                      "scale {:.3f}", report.index, baseline, world_from_map.scale);
  FinishInitialization(first, frame, created.first, created.second, created.num_points, report);
  report.message += " (from markers, in the world)";
  return true;
}

}  // namespace arucoslam
