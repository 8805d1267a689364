#include "arucoslam/slam/loop_closer.h"

#include <cmath>
#include <set>
#include <utility>

#include "arucoslam/feature/feature_grid.h"
#include "arucoslam/slam/projection_queries.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// A keypoint of `target` that should observe `loop_point`; `existing` is the point it held
// when matched (invalid for none).
struct FuseAction {
  KeyframeId target;
  int index = 0;
  MapPointId loop_point;
  MapPointId existing;
};

struct KeyframeMatches {
  bool found = false;
  CameraModel current_camera;
  CameraModel candidate_camera;
  Rigid3 candidate_cam_from_world;
  Rigid3 current_cam_from_world;
  std::vector<Sim3Correspondence> correspondences;
  std::vector<FuseAction> fusions;  // per correspondence: current keypoint -> candidate point
};

KeyframeMatches MatchKeyframes(const MapData& data, KeyframeId current_id, KeyframeId candidate_id,
                               const BruteForceMatchOptions& options) {
  KeyframeMatches result;
  const Keyframe* current = data.FindKeyframe(current_id);
  const Keyframe* candidate = data.FindKeyframe(candidate_id);
  if (current == nullptr || candidate == nullptr) return result;
  result.found = true;
  result.current_camera = current->camera;
  result.candidate_camera = candidate->camera;
  result.candidate_cam_from_world = candidate->cam_from_world;
  result.current_cam_from_world = current->cam_from_world;
  for (const FeatureMatch& match :
       MatchBruteForce(current->features, candidate->features, options)) {
    const MapPointId current_point = current->map_point_ids[match.index1];
    const MapPointId candidate_point = candidate->map_point_ids[match.index2];
    if (!current_point.IsValid() || !candidate_point.IsValid() ||
        current_point == candidate_point) {
      continue;
    }
    Sim3Correspondence c;
    c.p_in_current = current->cam_from_world * data.FindMapPoint(current_point)->p_in_world;
    c.p_in_candidate = candidate->cam_from_world * data.FindMapPoint(candidate_point)->p_in_world;
    if (!(c.p_in_current.z() > 0.0) || !(c.p_in_candidate.z() > 0.0)) continue;
    c.pixel_in_current = current->UndistortedPixel(match.index1);
    c.pixel_in_candidate = candidate->UndistortedPixel(match.index2);
    c.sigma_current_px = current->SigmaPx(match.index1);
    c.sigma_candidate_px = candidate->SigmaPx(match.index2);
    result.correspondences.push_back(c);
    result.fusions.push_back({current_id, match.index1, candidate_point, current_point});
  }
  return result;
}

std::vector<MapPointId> LoopSidePoints(const MapData& data, KeyframeId candidate, int neighbours) {
  std::set<MapPointId> points;
  std::vector<KeyframeId> keyframes = data.covisibility().BestCovisible(candidate, neighbours);
  keyframes.push_back(candidate);
  for (const KeyframeId& id : keyframes) {
    for (const MapPointId& point : data.MapPointsOf(id)) points.insert(point);
  }
  return {points.begin(), points.end()};
}

// Loop-side points projected into `target` posed at `cam_from_world` (its corrected Sim3)
// and matched by descriptor; one action per match that passes the reprojection test.
void ProjectLoopPoints(const MapData& data, const Keyframe& target, const Sim3& cam_from_world,
                       const std::vector<MapPointId>& loop_points, const LoopCloserOptions& options,
                       std::vector<FuseAction>* actions) {
  const ProjectionQueries set = UnobservedPointQueries(
      data, target, cam_from_world, cam_from_world.Inverse().translation, loop_points);
  if (set.queries.empty()) return;
  ProjectionMatchOptions match_options;
  match_options.base_radius_px = options.search_radius_px;
  match_options.max_distance = options.max_projection_distance;
  const FeatureGrid grid(target.features);
  for (const FeatureMatch& match :
       MatchByProjection(target.features, grid, set.queries, {}, match_options)) {
    const cv::Point2f& keypoint = target.features.keypoints[match.index2].pt;
    const double sigma = target.SigmaPx(match.index2);
    const Eigen::Vector2d error =
        set.queries[match.index1].pixel - Eigen::Vector2d(keypoint.x, keypoint.y);
    if (error.squaredNorm() > options.reprojection_chi2 * sigma * sigma) continue;
    actions->push_back(
        {target.id, match.index2, set.point_ids[match.index1], target.map_point_ids[match.index2]});
  }
}

// The loop-side point replaces the keypoint's point (or becomes its observation).
int ApplyFusion(MapData& data, const std::vector<FuseAction>& actions) {
  int fused = 0;
  std::set<MapPointId> touched;
  for (const FuseAction& action : actions) {
    const Keyframe* target = data.FindKeyframe(action.target);
    const MapPoint* point = data.FindMapPoint(action.loop_point);
    if (target == nullptr || point == nullptr) continue;
    const MapPointId now = target->map_point_ids[action.index];
    if (now != action.existing || now == action.loop_point) continue;
    if (point->observations.count(action.target) != 0) continue;
    if (now.IsValid() && data.FindMapPoint(now) != nullptr) {
      data.ReplaceMapPoint(now, action.loop_point);
    } else {
      data.AddObservation(action.target, action.index, action.loop_point);
    }
    touched.insert(action.loop_point);
    ++fused;
  }
  for (const MapPointId& id : touched) {
    if (data.FindMapPoint(id) == nullptr) continue;
    data.UpdateDescriptor(id);
    data.UpdateNormalAndDepth(id);
  }
  return fused;
}

using Neighbourhoods = std::map<KeyframeId, std::set<KeyframeId>>;

// Covisible keyframes of each corrected keyframe (taken before fusion).
Neighbourhoods NeighboursOf(const MapData& data, const std::map<KeyframeId, Sim3>& corrected) {
  Neighbourhoods neighbours;
  for (const auto& [id, pose] : corrected) {
    if (data.FindKeyframe(id) == nullptr) continue;
    for (const auto& [neighbour, weight] : data.covisibility().Neighbours(id)) {
      neighbours[id].insert(neighbour);
    }
  }
  return neighbours;
}

// Edges whose measurement comes from the corrected estimate: the solved loop, every link
// that fusion created from a corrected keyframe to one outside the corrected set sharing at
// least `min_weight` points (weaker links would tie the loop through a few fused points), and
// the loops closed before (both ends at their current estimate).
std::vector<LoopConstraint> LoopConnections(
    const MapData& data, const std::map<KeyframeId, Sim3>& corrected,
    const Neighbourhoods& before_fusion, const LoopConstraint& loop,
    const std::vector<std::pair<KeyframeId, KeyframeId>>& previous, int min_weight) {
  auto estimate = [&](KeyframeId id) {
    const auto it = corrected.find(id);
    return it != corrected.end() ? it->second : Sim3(data.FindKeyframe(id)->cam_from_world);
  };
  std::vector<LoopConstraint> constraints = {loop};
  for (const auto& [id, pose] : corrected) {
    if (data.FindKeyframe(id) == nullptr) continue;
    for (const auto& [neighbour, weight] : data.covisibility().Neighbours(id)) {
      if (corrected.count(neighbour) != 0 || weight < min_weight) continue;
      const auto before = before_fusion.find(id);
      if (before != before_fusion.end() && before->second.count(neighbour) != 0) continue;
      constraints.push_back({id, neighbour, estimate(neighbour) * pose.Inverse()});
    }
  }
  for (const auto& [a, b] : previous) {
    if (data.FindKeyframe(a) == nullptr || data.FindKeyframe(b) == nullptr) continue;
    constraints.push_back({a, b, estimate(b) * estimate(a).Inverse()});
  }
  return constraints;
}

}  // namespace

bool LoopCloserOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("matching", matching);
  check.Nested("sim3", sim3);
  check.AtLeast("loop_neighbours", loop_neighbours, 0);
  check.Above("search_radius_px", search_radius_px, 0.0);
  check.Above("max_projection_distance", max_projection_distance, 0);
  check.Above("reprojection_chi2", reprojection_chi2, 0.0);
  check.AtLeast("min_total_matches", min_total_matches, 3);
  check.Above("max_correction_rotation_deg", max_correction_rotation_deg, 0.0);
  check.AtLeast("correction_neighbours", correction_neighbours, 0);
  check.Nested("essential_graph", essential_graph);
  return check.ok();
}

LoopCloser::LoopCloser(Map& map, const LoopCloserOptions& options) : map_(map), options_(options) {
  SetMetricMap(options_.metric_map);
}

void LoopCloser::SetMetricMap(bool metric) {
  options_.metric_map = metric;
  options_.sim3.fix_scale = metric;
  options_.essential_graph.solver.fix_scale = metric;
}

void LoopCloser::SetPosePriors(PosePriorSource source, const EssentialGraphOptions& graph) {
  pose_priors_ = std::move(source);
  prior_graph_ = graph;
}

LoopClosureResult LoopCloser::CloseLoop(KeyframeId current, KeyframeId candidate) {
  LoopClosureResult result;
  if (!options_.Check()) {
    result.reason = "invalid options";
    return result;
  }
  const KeyframeMatches matches = map_.Read([&](const MapData& data) {
    return MatchKeyframes(data, current, candidate, options_.matching);
  });
  if (!matches.found) {
    result.reason = "unknown keyframe";
    return result;
  }
  result.num_matches = static_cast<int>(matches.correspondences.size());
  const Sim3SolverResult solved = SolveSim3(matches.current_camera, matches.candidate_camera,
                                            matches.correspondences, options_.sim3);
  result.num_sim3_inliers = solved.num_inliers;
  result.candidate_from_current = solved.candidate_from_current;
  if (!solved.success) {
    result.reason = "sim3: " + solved.message;
    return result;
  }
  const Sim3 current_corrected =
      solved.candidate_from_current.Inverse() * Sim3(matches.candidate_cam_from_world);
  result.correction_rotation_deg =
      RotationAngle(current_corrected.rotation.conjugate() *
                    matches.current_cam_from_world.rotation) * 180.0 / M_PI;
  if (result.correction_rotation_deg > options_.max_correction_rotation_deg) {
    result.reason = "correction rotation " + std::to_string(result.correction_rotation_deg) +
                    " deg";
    return result;
  }
  const std::map<KeyframeId, Sim3> corrected =
      PropagateLoopCorrection(map_, current, current_corrected, options_.correction_neighbours);

  std::vector<FuseAction> actions;
  std::set<int> inlier_indices;
  for (std::size_t i = 0; i < solved.inliers.size(); ++i) {
    if (!solved.inliers[i]) continue;
    actions.push_back(matches.fusions[i]);
    inlier_indices.insert(matches.fusions[i].index);
  }
  Neighbourhoods before_fusion;
  map_.Read([&](const MapData& data) {
    before_fusion = NeighboursOf(data, corrected);
    const std::vector<MapPointId> loop_points =
        LoopSidePoints(data, candidate, options_.loop_neighbours);
    for (const auto& [id, pose] : corrected) {
      std::vector<FuseAction> found;
      ProjectLoopPoints(data, *data.FindKeyframe(id), pose, loop_points, options_, &found);
      for (const FuseAction& action : found) {
        if (id == current && inlier_indices.count(action.index) != 0) continue;
        if (id == current) ++result.num_projected_matches;
        actions.push_back(action);
      }
    }
  });
  if (result.num_sim3_inliers + result.num_projected_matches < options_.min_total_matches) {
    result.reason = "too few matches after projection";
    return result;
  }
  result.num_fused_points = map_.Write([&](MapData& data) { return ApplyFusion(data, actions); });
  const std::vector<LoopConstraint> constraints = map_.Read([&](const MapData& data) {
    return LoopConnections(data, corrected, before_fusion,
                           {current, candidate, solved.candidate_from_current}, closed_loops_,
                           options_.essential_graph.min_covisibility_weight);
  });
  result.num_corrected_keyframes = static_cast<int>(corrected.size());
  const std::vector<KeyframePosePrior> priors =
      pose_priors_ ? pose_priors_() : std::vector<KeyframePosePrior>();
  if (priors.empty()) {
    result.essential_graph = OptimizeEssentialGraph(map_, candidate, constraints, corrected, {},
                                                    options_.essential_graph);
  } else {
    EssentialGraphOptions graph = prior_graph_;
    graph.solver = options_.essential_graph.solver;
    graph.min_covisibility_weight = options_.essential_graph.min_covisibility_weight;
    result.essential_graph =
        OptimizeEssentialGraph(map_, KeyframeId(), constraints, corrected, priors, graph);
  }
  if (!result.essential_graph.applied) {
    result.reason = "essential graph: " + result.essential_graph.summary.message;
    return result;
  }
  result.closed = true;
  closed_loops_.emplace_back(current, candidate);
  global_bundle_adjustment_requested_ = true;
  return result;
}

}  // namespace arucoslam
