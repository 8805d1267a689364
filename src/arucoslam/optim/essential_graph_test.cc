#include "arucoslam/optim/essential_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "arucoslam/optim/synthetic_loop.h"

namespace arucoslam {
namespace {

constexpr int kPointsPerKeyframe = 150;  // shared with the next keyframe (strong edge)
constexpr int kPointsSeenTwoAhead = 40;  // of those, also seen two keyframes ahead (weak)

// A map whose keyframes are the drifted estimate of the synthetic loop. Each keyframe
// creates points in front of it (its estimate's local scale, as monocular mapping would),
// seen by it and the next keyframe, some also two ahead. Truth positions kept per point.
struct LoopMap {
  SyntheticLoop loop;
  std::vector<double> local_scales;  // per keyframe
  Map map;
  std::vector<KeyframeId> keyframes;
  std::vector<MapPointId> points;
  std::vector<Eigen::Vector3d> truth_points;
};

Keyframe MakeKeyframe(const Rigid3& cam_from_world, int num_keypoints) {
  Keyframe keyframe;
  keyframe.camera = PinholeCamera(640, 480, 500.0);
  keyframe.cam_from_world = cam_from_world;
  keyframe.features.pyramid = ScalePyramid::Make(8, 1.2);
  for (int i = 0; i < num_keypoints; ++i) {
    cv::KeyPoint keypoint(100.0f, 100.0f, 31.0f);
    keypoint.octave = 0;
    keyframe.features.keypoints.push_back(keypoint);
    keyframe.features.undistorted.emplace_back(0.0, 0.0);
  }
  keyframe.features.descriptors = cv::Mat::zeros(num_keypoints, kOrbDescriptorBytes, CV_8U);
  keyframe.map_point_ids.assign(num_keypoints, MapPointId());
  return keyframe;
}

void Build(LoopMap& scene, const SyntheticLoopOptions& options) {
  scene.loop = MakeSyntheticLoop(options);
  const int n = options.num_keyframes;
  double scale = 1.0;
  for (int i = 0; i < n; ++i, scale *= options.scale_drift) scene.local_scales.push_back(scale);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  scene.map.Write([&](MapData& data) {
    for (int i = 0; i < n; ++i) {
      const Rigid3 estimate(scene.loop.problem.nodes[i].cam_from_world.rotation,
                            scene.loop.problem.nodes[i].cam_from_world.translation);
      scene.keyframes.push_back(data.AddKeyframe(MakeKeyframe(estimate, 3 * kPointsPerKeyframe)));
    }
    std::vector<int> next_slot(n, 0);
    for (int i = 0; i < n; ++i) {
      const Rigid3 estimate_world_from_cam =
          data.FindKeyframe(scene.keyframes[i])->cam_from_world.Inverse();
      for (int k = 0; k < kPointsPerKeyframe; ++k) {
        const double z = 2.0 + 4.0 * unit(random);
        const Eigen::Vector3d in_cam((unit(random) - 0.5) * z, (unit(random) - 0.5) * z, z);
        MapPoint point;
        point.p_in_world = estimate_world_from_cam * (scene.local_scales[i] * in_cam);
        point.reference_keyframe = scene.keyframes[i];
        const MapPointId id = data.AddMapPoint(point);
        scene.points.push_back(id);
        scene.truth_points.push_back(scene.loop.truth_cam_from_world[i].Inverse() * in_cam);
        const int last = k < kPointsSeenTwoAhead ? i + 2 : i + 1;
        for (int j = i; j <= last && j < n; ++j) {
          EXPECT_TRUE(data.AddObservation(scene.keyframes[j], next_slot[j]++, id));
        }
      }
    }
  });
}

double PointRms(const LoopMap& scene) {
  return scene.map.Read([&](const MapData& data) {
    double sum = 0.0;
    for (std::size_t j = 0; j < scene.points.size(); ++j) {
      sum += (data.FindMapPoint(scene.points[j])->p_in_world - scene.truth_points[j]).squaredNorm();
    }
    return std::sqrt(sum / scene.points.size());
  });
}

double KeyframeRms(const LoopMap& scene) {
  return scene.map.Read([&](const MapData& data) {
    double sum = 0.0;
    for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
      sum += (data.FindKeyframe(scene.keyframes[i])->CameraCenter() -
              scene.loop.truth_cam_from_world[i].Inverse().translation)
                 .squaredNorm();
    }
    return std::sqrt(sum / scene.keyframes.size());
  });
}

TEST(EssentialGraphTest, ClosingTheLoopCorrectsKeyframesAndPoints) {
  LoopMap scene;
  Build(scene, {});
  const LoopConstraint loop{scene.keyframes.back(), scene.keyframes.front(),
                            scene.loop.problem.edges.back().to_from_from};
  const double keyframes_before = KeyframeRms(scene);
  const double points_before = PointRms(scene);
  // The current keyframe's neighbourhood moved by the loop Sim3 first, as loop closing does.
  const Sim3 current_corrected =
      loop.candidate_from_current.Inverse() * Sim3(scene.map.Read([&](const MapData& data) {
        return data.FindKeyframe(loop.candidate)->cam_from_world;
      }));
  const auto corrected = PropagateLoopCorrection(scene.map, loop.current, current_corrected, 5);
  EXPECT_EQ(corrected.size(), 3u);  // current and its two covisible keyframes
  const EssentialGraphResult result =
      OptimizeEssentialGraph(scene.map, loop.candidate, {loop}, corrected);
  ASSERT_TRUE(result.applied) << result.summary.message;
  EXPECT_EQ(result.num_keyframes, 40);
  EXPECT_EQ(result.num_loop_edges, 1);
  EXPECT_EQ(result.num_tree_edges, 39);         // every keyframe but the first has a parent
  EXPECT_EQ(result.num_covisibility_edges, 0);  // i-(i+2) share 40 < 100 points
  EXPECT_EQ(result.num_corrected_points, static_cast<int>(scene.points.size()));
  const double keyframes_after = KeyframeRms(scene);
  const double points_after = PointRms(scene);
  std::printf("keyframe centres RMS %.3f -> %.3f m, points RMS %.3f -> %.3f m\n", keyframes_before,
              keyframes_after, points_before, points_after);
  EXPECT_LT(keyframes_after, keyframes_before / 5.0);
  EXPECT_LT(points_after, points_before / 5.0);
  EXPECT_EQ(scene.map.Read([](const MapData& data) { return data.CheckInvariants(); }), "");
}

// The scale change reported per keyframe undoes its drift (1.01 per keyframe, 1.47 at the
// end): map units per metre around keyframe i become local_scale[i] x its scale change, the
// loop keyframe's (1) everywhere once corrected.
TEST(EssentialGraphTest, ScaleChangesUndoTheScaleDrift) {
  LoopMap scene;
  Build(scene, {});
  const LoopConstraint loop{scene.keyframes.back(), scene.keyframes.front(),
                            scene.loop.problem.edges.back().to_from_from};
  const EssentialGraphResult result = OptimizeEssentialGraph(scene.map, loop.candidate, {loop});
  ASSERT_TRUE(result.applied) << result.summary.message;
  ASSERT_EQ(result.scale_changes.size(), scene.keyframes.size());
  double worst_before = 0.0, worst_after = 0.0;
  for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
    const double change = result.scale_changes.at(scene.keyframes[i]);
    worst_before = std::max(worst_before, std::abs(std::log(scene.local_scales[i])));
    worst_after = std::max(worst_after, std::abs(std::log(scene.local_scales[i] * change)));
  }
  std::printf("largest local scale error %.3f -> %.3f (log)\n", worst_before, worst_after);
  EXPECT_DOUBLE_EQ(result.scale_changes.at(loop.candidate), 1.0);  // the fixed keyframe
  EXPECT_LT(worst_after, worst_before / 5.0);
}

TEST(EssentialGraphTest, WeakerCovisibilityThresholdAddsEdges) {
  LoopMap scene;
  Build(scene, {});
  EssentialGraphOptions options;
  options.min_covisibility_weight = 30;
  const LoopConstraint loop{scene.keyframes.back(), scene.keyframes.front(),
                            scene.loop.problem.edges.back().to_from_from};
  const EssentialGraphResult result =
      OptimizeEssentialGraph(scene.map, loop.candidate, {loop}, {}, {}, options);
  ASSERT_TRUE(result.applied) << result.summary.message;
  EXPECT_EQ(result.num_tree_edges + result.num_covisibility_edges, 39 + 38);
}

TEST(EssentialGraphTest, MarkerPriorsCorrectAMetricMapWithoutALoop) {
  SyntheticLoopOptions options;
  options.scale_drift = 1.0;
  options.scale_in_loop_edge = false;
  LoopMap scene;
  Build(scene, options);
  std::vector<KeyframePosePrior> priors;
  for (int i = 0; i < 40; i += 10) {
    priors.push_back({scene.keyframes[i], scene.loop.truth_cam_from_world[i].Inverse(),
                      100.0 * Matrix6d::Identity()});
  }
  EssentialGraphOptions graph_options;
  graph_options.solver.fix_scale = true;
  const double before = KeyframeRms(scene);
  const EssentialGraphResult result =
      OptimizeEssentialGraph(scene.map, KeyframeId(), {}, {}, priors, graph_options);
  ASSERT_TRUE(result.applied) << result.summary.message;
  EXPECT_EQ(result.num_priors, 4);
  const double after = KeyframeRms(scene);
  std::printf("metric map with priors: keyframe centres RMS %.3f -> %.3f m\n", before, after);
  EXPECT_LT(after, before / 5.0);
}

// Monocular drift between two marker sightings (keyframes 0-3 and 20-23, as a robot passing
// two docks): a Sim3 graph with the sightings as priors stretches the keyframes between them
// back (their scale drift included) and moves the points with their keyframes.
TEST(EssentialGraphTest, MarkerPriorsAtTwoSightingsCorrectTheScaleDriftBetweenThem) {
  SyntheticLoopOptions options;
  options.scale_drift = 1.02;
  options.yaw_drift_rad = 0.004;
  options.scale_in_loop_edge = false;
  LoopMap scene;
  Build(scene, options);
  std::vector<KeyframePosePrior> priors;
  for (const int first : {0, 20}) {
    for (int i = first; i < first + 4; ++i) {
      priors.push_back({scene.keyframes[i], scene.loop.truth_cam_from_world[i].Inverse(),
                        1e4 * Matrix6d::Identity()});  // 1 cm, 0.01 rad
    }
  }
  const auto between_rms = [&] {
    return scene.map.Read([&](const MapData& data) {
      double sum = 0.0;
      for (int i = 4; i < 20; ++i) {
        sum += (data.FindKeyframe(scene.keyframes[i])->CameraCenter() -
                scene.loop.truth_cam_from_world[i].Inverse().translation)
                   .squaredNorm();
      }
      return std::sqrt(sum / 16.0);
    });
  };
  EssentialGraphOptions graph_options;
  graph_options.edge_translation_sigma = 0.02;
  graph_options.edge_rotation_sigma = 0.005;
  graph_options.edge_scale_sigma = 0.01;
  const double before = between_rms();
  const double points_before = PointRms(scene);
  const EssentialGraphResult result =
      OptimizeEssentialGraph(scene.map, KeyframeId(), {}, {}, priors, graph_options);
  ASSERT_TRUE(result.applied) << result.summary.message;
  EXPECT_EQ(result.num_priors, 8);
  const double after = between_rms();
  std::printf("two sightings: keyframe centres between them RMS %.3f -> %.3f m, points %.3f -> "
              "%.3f m\n", before, after, points_before, PointRms(scene));
  EXPECT_LT(after, before / 4.0);
  EXPECT_LT(PointRms(scene), points_before / 2.0);
}

// Held keyframes (a merged map already in the world) keep their poses exactly while the
// priors correct the rest.
TEST(EssentialGraphTest, HeldKeyframesDoNotMove) {
  SyntheticLoopOptions options;
  options.scale_drift = 1.02;
  options.scale_in_loop_edge = false;
  LoopMap scene;
  Build(scene, options);
  std::set<KeyframeId> held;
  for (int i = 0; i < 10; ++i) held.insert(scene.keyframes[i]);
  std::vector<KeyframePosePrior> priors;
  for (int i = 20; i < 40; i += 5) {
    priors.push_back({scene.keyframes[i], scene.loop.truth_cam_from_world[i].Inverse(),
                      1e4 * Matrix6d::Identity()});
  }
  const auto centres = [&] {
    return scene.map.Read([&](const MapData& data) {
      std::vector<Eigen::Vector3d> result;
      for (const KeyframeId& id : scene.keyframes) {
        result.push_back(data.FindKeyframe(id)->CameraCenter());
      }
      return result;
    });
  };
  const std::vector<Eigen::Vector3d> before = centres();
  const EssentialGraphResult result = OptimizeEssentialGraph(scene.map, KeyframeId(), {}, {},
                                                             priors, EssentialGraphOptions{}, held);
  ASSERT_TRUE(result.applied) << result.summary.message;
  const std::vector<Eigen::Vector3d> after = centres();
  for (int i = 0; i < 10; ++i) EXPECT_LT((after[i] - before[i]).norm(), 1e-9) << i;
  double moved = 0.0;
  for (int i = 20; i < 40; ++i) moved = std::max(moved, (after[i] - before[i]).norm());
  EXPECT_GT(moved, 0.05);  // the priors (scale drift 2% per keyframe) did move the rest
}

TEST(EssentialGraphTest, EdgeSigmasMustBePositive) {
  EssentialGraphOptions options;
  EXPECT_TRUE(options.Check());
  options.edge_scale_sigma = 0.0;
  EXPECT_FALSE(options.Check());
  options.edge_scale_sigma = 0.01;
  options.edge_rotation_sigma = -1.0;
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace arucoslam
