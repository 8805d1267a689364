#include "arucoslam/slam/map_initialization.h"

#include <algorithm>
#include <vector>

namespace arucoslam {
namespace {

// Both views of the initial points, refined together; camera 1 stays fixed.
BundleAdjustmentProblem MakeProblem(const Frame& frame1, const Frame& frame2,
                                    const InitializationResult& initialization, bool hold_motion) {
  BundleAdjustmentProblem problem;
  problem.intrinsics = PinholeIntrinsics::FromCamera(frame1.camera);
  problem.poses.push_back({Rigid3::Identity(), true});
  problem.poses.push_back({initialization.cam2_from_cam1, hold_motion});
  for (std::size_t k = 0; k < initialization.matches.size(); ++k) {
    const FeatureMatch& match = initialization.matches[k];
    problem.points.push_back({initialization.points_in_cam1[k], false});
    problem.observations.push_back(
        {0, k, frame1.UndistortedPixel(match.index1), frame1.SigmaPx(match.index1)});
    problem.observations.push_back(
        {1, k, frame2.UndistortedPixel(match.index2), frame2.SigmaPx(match.index2)});
  }
  return problem;
}

}  // namespace

InitialMapResult CreateInitialMap(Map& map, Frame& frame1, Frame& frame2,
                                  const InitializationResult& initialization,
                                  const InitialMapOptions& options) {
  InitialMapResult result;
  if (!initialization.success ||
      initialization.matches.size() != initialization.points_in_cam1.size()) {
    result.message = "initialisation did not succeed";
    return result;
  }
  BundleAdjustmentProblem problem =
      MakeProblem(frame1, frame2, initialization, options.hold_motion);
  const BundleAdjustmentSummary summary =
      SolveBundleAdjustment(options.bundle_adjustment, &problem);
  if (!summary.success) {
    result.message = "bundle adjustment failed: " + summary.message;
    return result;
  }
  // Keep points whose two observations pass the chi-square test and lie in front of camera 1.
  std::vector<std::size_t> kept;
  std::vector<double> depths;
  for (std::size_t k = 0; k < problem.points.size(); ++k) {
    if (summary.outliers[2 * k] || summary.outliers[2 * k + 1]) continue;
    const double depth = problem.points[k].p_in_world.z();
    if (!(depth > 0.0)) continue;
    kept.push_back(k);
    depths.push_back(depth);
  }
  if (static_cast<int>(kept.size()) < std::max(options.min_points, 1)) {
    result.message = "only " + std::to_string(kept.size()) + " points survive refinement";
    return result;
  }
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  const double scale = 1.0 / depths[depths.size() / 2];
  Rigid3 cam2_from_world = problem.poses[1].cam_from_world;
  cam2_from_world.translation *= scale;

  frame1.ResetMatches();
  frame2.ResetMatches();
  frame1.cam_from_world = Rigid3::Identity();
  frame2.cam_from_world = cam2_from_world;
  map.Write([&](MapData& data) {
    result.first = data.AddKeyframe(Keyframe::FromFrame(frame1));
    result.second = data.AddKeyframe(Keyframe::FromFrame(frame2), result.first);
    for (std::size_t k : kept) {
      const FeatureMatch& match = initialization.matches[k];
      MapPoint point;
      point.p_in_world = scale * problem.points[k].p_in_world;
      point.reference_keyframe = result.first;
      const MapPointId id = data.AddMapPoint(point);
      data.AddObservation(result.first, match.index1, id);
      data.AddObservation(result.second, match.index2, id);
      data.UpdateDescriptor(id);
      data.UpdateNormalAndDepth(id);
      frame1.map_point_ids[match.index1] = id;
      frame2.map_point_ids[match.index2] = id;
    }
  });
  result.success = true;
  result.num_points = static_cast<int>(kept.size());
  return result;
}

}  // namespace arucoslam
