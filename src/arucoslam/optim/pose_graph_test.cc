#include "arucoslam/optim/pose_graph.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <random>

#include "arucoslam/optim/pose_graph_residuals.h"
#include "arucoslam/optim/synthetic_loop.h"

namespace arucoslam {
namespace {

using pose_graph_internal::SimilarityT;

Sim3 RandomSim3(std::mt19937& random, double angle, double log_scale) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Vector3d axis =
      Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
  return Sim3(std::exp(log_scale), Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis)),
              Eigen::Vector3d(normal(random), normal(random), normal(random)));
}

TEST(PoseGraphResidualsTest, TemplatedLogMatchesSim3Log) {
  std::mt19937 random(1);
  for (double angle : {0.0, 1e-9, 1e-4, 5e-3, 0.3, 2.0, 3.1}) {
    for (double log_scale : {0.0, 1e-9, -3e-3, 5e-3, 0.4, -1.2}) {
      const Sim3 s = RandomSim3(random, angle, log_scale);
      const Vector7d expected = s.Log();
      const Vector7d got = pose_graph_internal::LogSimilarity(
          SimilarityT<double>{s.scale, s.rotation, s.translation});
      EXPECT_LT((got - expected).norm(), 1e-9 * (1.0 + expected.norm()))
          << "angle " << angle << " log scale " << log_scale;
    }
  }
}

// The automatic derivatives of the relative error (through every branch of the templated
// log) agree with central differences of the double version.
TEST(PoseGraphResidualsTest, JetDerivativesMatchNumericDifferences) {
  using Jet = ceres::Jet<double, 7>;
  std::mt19937 random(2);
  const Sim3 measured = RandomSim3(random, 0.4, 0.2);
  const Sim3 j_from_world = RandomSim3(random, 1.0, 0.1);
  for (double error_size : {0.0, 1e-3, 0.5}) {
    // i chosen so that the error has about `error_size` in every component.
    const Sim3 error = Sim3::Exp(Vector7d::Constant(error_size));
    const Sim3 i_from_world = measured.Inverse() * error * j_from_world;
    auto evaluate = [&](const Vector7d& delta) {
      const Sim3 perturbed = Sim3::Exp(delta) * i_from_world;
      return pose_graph_internal::RelativeSimilarityError(
          SimilarityT<double>{measured.scale, measured.rotation, measured.translation},
          SimilarityT<double>{perturbed.scale, perturbed.rotation, perturbed.translation},
          SimilarityT<double>{j_from_world.scale, j_from_world.rotation, j_from_world.translation});
    };
    // Jets: the perturbation of i as Exp(delta) * S_i, to first order
    // [I + delta^] * S_i: scale (1 + sigma), rotation (I + omega^), translation shifted.
    SimilarityT<Jet> i_jet;
    Eigen::Matrix<Jet, 3, 1> upsilon, omega;
    for (int k = 0; k < 3; ++k) {
      upsilon[k] = Jet(0.0, k);
      omega[k] = Jet(0.0, 3 + k);
    }
    const Jet sigma(0.0, 6);
    const SimilarityT<Jet> left{
        exp(sigma),
        Eigen::Quaternion<Jet>(Jet(1.0), 0.5 * omega[0], 0.5 * omega[1], 0.5 * omega[2]), upsilon};
    i_jet = left * SimilarityT<Jet>{Jet(i_from_world.scale), i_from_world.rotation.cast<Jet>(),
                                    i_from_world.translation.cast<Jet>()};
    const auto jet_error = pose_graph_internal::RelativeSimilarityError(
        SimilarityT<Jet>{Jet(measured.scale), measured.rotation.cast<Jet>(),
                         measured.translation.cast<Jet>()},
        i_jet,
        SimilarityT<Jet>{Jet(j_from_world.scale), j_from_world.rotation.cast<Jet>(),
                         j_from_world.translation.cast<Jet>()});
    constexpr double kStep = 1e-6;
    for (int c = 0; c < 7; ++c) {
      Vector7d step = Vector7d::Zero();
      step[c] = kStep;
      const Vector7d numeric = (evaluate(step) - evaluate(-step)) / (2.0 * kStep);
      for (int r = 0; r < 7; ++r) {
        EXPECT_NEAR(jet_error[r].v[c], numeric[r], 1e-6)
            << "error size " << error_size << " row " << r << " col " << c;
      }
    }
  }
}

TEST(PoseGraphTest, ConsistentGraphHasZeroCostAndStaysPut) {
  SyntheticLoopOptions options;
  options.yaw_drift_rad = 0.0;
  options.scale_drift = 1.0;
  SyntheticLoop loop = MakeSyntheticLoop(options);
  EXPECT_LT(PoseGraphChiSquare(loop.problem), 1e-18);
  const PoseGraphSummary summary = SolvePoseGraph({}, &loop.problem);
  ASSERT_TRUE(summary.success) << summary.message;
  EXPECT_LT(CameraCentreRms(loop.problem, loop.truth_cam_from_world), 1e-9);
}

TEST(PoseGraphTest, LoopEdgeRemovesRotationAndScaleDrift) {
  SyntheticLoop loop = MakeSyntheticLoop({});  // 40 keyframes, 0.01 rad and 1% per step
  const double before = CameraCentreRms(loop.problem, loop.truth_cam_from_world);
  const PoseGraphSummary summary = SolvePoseGraph({}, &loop.problem);
  ASSERT_TRUE(summary.success) << summary.message;
  const double after = CameraCentreRms(loop.problem, loop.truth_cam_from_world);
  RecordProperty("rms_before_m", std::to_string(before));
  RecordProperty("rms_after_m", std::to_string(after));
  std::printf("camera centre RMS: %.3f m before, %.3f m after (%.1fx)\n", before, after,
              before / after);
  EXPECT_GT(before, 2.0);  // the drift is substantial on a 10 m circle
  EXPECT_LT(after, before / 5.0);
  EXPECT_LT(summary.final_cost, 1e-2 * summary.initial_cost);
}

TEST(PoseGraphTest, AbsolutePriorsFixAMetricGraphWithoutAFixedNode) {
  SyntheticLoopOptions options;
  options.scale_drift = 1.0;  // metric map: rotation drift only
  options.scale_in_loop_edge = false;
  SyntheticLoop loop = MakeSyntheticLoop(options);
  loop.problem.edges.pop_back();  // no loop edge: the priors alone correct the drift
  loop.problem.nodes[0].fixed = false;
  for (std::size_t i = 0; i < loop.truth_cam_from_world.size(); i += 10) {
    PoseGraphProblem::PosePrior prior;
    prior.node = i;
    prior.world_from_cam = loop.truth_cam_from_world[i].Inverse();
    prior.information = 100.0 * Matrix6d::Identity();
    loop.problem.priors.push_back(prior);
  }
  PoseGraphOptions solver;
  solver.fix_scale = true;
  const double before = CameraCentreRms(loop.problem, loop.truth_cam_from_world);
  const PoseGraphSummary summary = SolvePoseGraph(solver, &loop.problem);
  ASSERT_TRUE(summary.success) << summary.message;
  const double after = CameraCentreRms(loop.problem, loop.truth_cam_from_world);
  std::printf("with priors every 10 keyframes: %.3f m before, %.3f m after\n", before, after);
  EXPECT_LT(after, before / 5.0);
  for (const auto& node : loop.problem.nodes) EXPECT_EQ(node.cam_from_world.scale, 1.0);
  for (const auto& prior : loop.problem.priors) {
    const Eigen::Vector3d centre =
        loop.problem.nodes[prior.node].cam_from_world.Inverse().translation;
    EXPECT_LT((centre - prior.world_from_cam.translation).norm(), 0.1);
  }
}

TEST(PoseGraphTest, CheckRejectsBadProblems) {
  SyntheticLoop loop = MakeSyntheticLoop({});
  std::string reason;
  EXPECT_TRUE(loop.problem.Check(&reason)) << reason;
  PoseGraphProblem bad = loop.problem;
  bad.edges[0].to = bad.nodes.size();
  EXPECT_FALSE(bad.Check(&reason));
  bad = loop.problem;
  bad.edges[0].from = bad.edges[0].to;
  EXPECT_FALSE(bad.Check());
  bad = loop.problem;
  bad.edges[0].information(0, 1) = 0.5;  // not symmetric
  EXPECT_FALSE(bad.Check());
  bad = loop.problem;
  bad.edges[0].information(2, 2) = -1.0;  // not positive definite
  EXPECT_FALSE(bad.Check());
  bad = loop.problem;
  bad.priors.push_back({0, Rigid3(), -Matrix6d::Identity()});
  EXPECT_FALSE(bad.Check());
  EXPECT_FALSE(SolvePoseGraph({}, &bad).success);
  PoseGraphOptions options;
  options.max_iterations = 0;
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace arucoslam
