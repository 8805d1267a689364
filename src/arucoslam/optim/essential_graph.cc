#include "arucoslam/optim/essential_graph.h"

#include <set>
#include <utility>

namespace arucoslam {
namespace {

struct EssentialGraph {
  PoseGraphProblem problem;
  std::vector<KeyframeId> ids;  // per node
  std::map<KeyframeId, std::size_t> index;
  std::vector<Sim3> uncorrected;  // per node: the map's pose when the graph was built
  EssentialGraphResult counts;
};

Matrix7d EdgeInformation(const EssentialGraphOptions& options) {
  Matrix7d information = Matrix7d::Zero();
  const auto inverse_square = [](double sigma) { return 1.0 / (sigma * sigma); };
  information.diagonal() << Eigen::Vector3d::Constant(inverse_square(options.edge_translation_sigma)),
      Eigen::Vector3d::Constant(inverse_square(options.edge_rotation_sigma)),
      inverse_square(options.edge_scale_sigma);
  return information;
}

void AddEdge(EssentialGraph& graph, KeyframeId from, KeyframeId to, const Sim3& to_from_from,
             const Matrix7d& information) {
  PoseGraphProblem::Edge edge;
  edge.from = graph.index.at(from);
  edge.to = graph.index.at(to);
  edge.to_from_from = to_from_from;
  edge.information = information;
  graph.problem.edges.push_back(edge);
}

EssentialGraph Build(const MapData& data, KeyframeId fixed_keyframe,
                     const std::vector<LoopConstraint>& loops,
                     const std::map<KeyframeId, Sim3>& corrected,
                     const std::vector<KeyframePosePrior>& priors,
                     const EssentialGraphOptions& options,
                     const std::set<KeyframeId>& held_keyframes) {
  EssentialGraph graph;
  const Matrix7d information = EdgeInformation(options);
  for (const auto& [id, keyframe] : data.keyframes()) {
    graph.index[id] = graph.ids.size();
    graph.ids.push_back(id);
    graph.uncorrected.emplace_back(keyframe.cam_from_world);
    const auto it = corrected.find(id);
    graph.problem.nodes.push_back(
        {it != corrected.end() ? it->second : Sim3(keyframe.cam_from_world),
         id == fixed_keyframe || held_keyframes.count(id) != 0});
  }
  auto relative = [&](KeyframeId from, KeyframeId to) {
    return graph.uncorrected[graph.index.at(to)] *
           graph.uncorrected[graph.index.at(from)].Inverse();
  };
  std::set<std::pair<KeyframeId, KeyframeId>> linked;
  auto link = [&](KeyframeId a, KeyframeId b) {
    return linked.insert(a < b ? std::make_pair(a, b) : std::make_pair(b, a)).second;
  };
  for (const LoopConstraint& loop : loops) {
    if (graph.index.count(loop.current) == 0 || graph.index.count(loop.candidate) == 0) continue;
    if (!link(loop.current, loop.candidate)) continue;
    AddEdge(graph, loop.current, loop.candidate, loop.candidate_from_current, information);
    ++graph.counts.num_loop_edges;
  }
  const CovisibilityGraph& covisibility = data.covisibility();
  for (const KeyframeId& id : graph.ids) {
    const KeyframeId parent = covisibility.Parent(id);
    if (parent.IsValid() && graph.index.count(parent) != 0 && link(parent, id)) {
      AddEdge(graph, parent, id, relative(parent, id), information);
      ++graph.counts.num_tree_edges;
    }
    for (const KeyframeId& other :
         covisibility.CovisibleWithMinWeight(id, options.min_covisibility_weight)) {
      if (other < id && graph.index.count(other) != 0 && link(other, id)) {
        AddEdge(graph, other, id, relative(other, id), information);
        ++graph.counts.num_covisibility_edges;
      }
    }
  }
  for (const KeyframePosePrior& prior : priors) {
    const auto it = graph.index.find(prior.keyframe);
    if (it == graph.index.end()) continue;
    graph.problem.priors.push_back({it->second, prior.world_from_cam, prior.information});
    ++graph.counts.num_priors;
  }
  graph.counts.num_keyframes = static_cast<int>(graph.ids.size());
  return graph;
}

// world_new_from_world_old of a keyframe: its own node's, else its nearest spanning-tree
// ancestor's (keyframes added during the solve); identity when none is in the graph.
Sim3 WorldCorrection(const MapData& data, const EssentialGraph& graph, KeyframeId id) {
  for (int depth = 0; id.IsValid() && depth < 1000000; ++depth) {
    const auto it = graph.index.find(id);
    if (it != graph.index.end()) {
      return graph.problem.nodes[it->second].cam_from_world.Inverse() *
             graph.uncorrected[it->second];
    }
    id = data.covisibility().Contains(id) ? data.covisibility().Parent(id) : KeyframeId();
  }
  return Sim3();
}

Rigid3 ToRigid(const Sim3& cam_from_world) {
  return Rigid3(cam_from_world.rotation, cam_from_world.translation / cam_from_world.scale);
}

int Apply(MapData& data, const EssentialGraph& graph, std::map<KeyframeId, double>* scales) {
  std::map<KeyframeId, Sim3> corrections;
  for (const auto& [id, keyframe] : data.keyframes()) {
    corrections[id] = WorldCorrection(data, graph, id);
    (*scales)[id] = corrections[id].scale;
  }
  for (const auto& [id, correction] : corrections) {
    const Keyframe* keyframe = data.FindKeyframe(id);
    // cam_from_world_new = cam_from_world_old * world_old_from_world_new.
    data.SetKeyframePose(id, ToRigid(Sim3(keyframe->cam_from_world) * correction.Inverse()));
  }
  std::vector<std::pair<MapPointId, Eigen::Vector3d>> moved;
  for (const auto& [id, point] : data.map_points()) {
    KeyframeId reference = point.reference_keyframe;
    if (corrections.count(reference) == 0) {
      if (point.observations.empty()) continue;
      reference = point.observations.begin()->first;
    }
    moved.emplace_back(id, corrections.at(reference) * point.p_in_world);
  }
  for (const auto& [id, position] : moved) {
    data.SetMapPointPosition(id, position);
    data.UpdateNormalAndDepth(id);
  }
  return static_cast<int>(moved.size());
}

}  // namespace

std::map<KeyframeId, Sim3> PropagateLoopCorrection(const Map& map, KeyframeId current,
                                                   const Sim3& current_cam_from_world_corrected,
                                                   int num_neighbours) {
  return map.Read([&](const MapData& data) {
    std::map<KeyframeId, Sim3> corrected;
    const Keyframe* keyframe = data.FindKeyframe(current);
    if (keyframe == nullptr) return corrected;
    corrected[current] = current_cam_from_world_corrected;
    const Rigid3 world_from_current = keyframe->cam_from_world.Inverse();
    for (const KeyframeId& id : data.covisibility().BestCovisible(current, num_neighbours)) {
      const Rigid3 neighbour_from_current =
          data.FindKeyframe(id)->cam_from_world * world_from_current;
      corrected[id] = Sim3(neighbour_from_current) * current_cam_from_world_corrected;
    }
    return corrected;
  });
}

EssentialGraphResult OptimizeEssentialGraph(Map& map, KeyframeId fixed_keyframe,
                                            const std::vector<LoopConstraint>& loops,
                                            const std::map<KeyframeId, Sim3>& corrected,
                                            const std::vector<KeyframePosePrior>& priors,
                                            const EssentialGraphOptions& options,
                                            const std::set<KeyframeId>& held_keyframes) {
  if (!options.Check()) {
    EssentialGraphResult result;
    result.summary.message = "invalid options";
    return result;
  }
  EssentialGraph graph = map.Read([&](const MapData& data) {
    return Build(data, fixed_keyframe, loops, corrected, priors, options, held_keyframes);
  });
  EssentialGraphResult result = graph.counts;
  result.summary = SolvePoseGraph(options.solver, &graph.problem);
  if (!result.summary.success) return result;
  result.num_corrected_points =
      map.Write([&](MapData& data) { return Apply(data, graph, &result.scale_changes); });
  result.applied = true;
  return result;
}

}  // namespace arucoslam
