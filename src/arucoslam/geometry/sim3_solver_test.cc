#include "arucoslam/geometry/sim3_solver.h"

#include <gtest/gtest.h>

#include <random>

#include "arucoslam/geometry/camera.h"

namespace arucoslam {
namespace {

CameraModel MakeCamera() {
  return PinholeCamera(640, 480, 500.0);
}

Eigen::Vector2d Project(const CameraModel& camera, const Eigen::Vector3d& p) {
  return {camera.fx * p.x() / p.z() + camera.cx, camera.fy * p.y() / p.z() + camera.cy};
}

struct Scene {
  std::vector<Sim3Correspondence> correspondences;
  std::vector<bool> is_outlier;
};

// Points 2-6 m in front of the current camera, seen by the candidate through `truth`; pixel
// noise 0.5 px, depth noise 1% along each keyframe's ray (triangulation error); a fraction of
// matches are wrong: the candidate side is another, self-consistent point.
Scene MakeScene(const Sim3& candidate_from_current, int count, double outlier_fraction,
                unsigned seed) {
  const CameraModel camera = MakeCamera();
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto random_point = [&](double scale) -> Eigen::Vector3d {
    const double z = 2.0 + 4.0 * unit(random);
    return scale *
           Eigen::Vector3d((unit(random) - 0.5) * 1.1 * z, (unit(random) - 0.5) * 0.8 * z, z);
  };
  auto noise2 = [&](double sigma) -> Eigen::Vector2d {
    return sigma * Eigen::Vector2d(normal(random), normal(random));
  };
  Scene scene;
  for (int i = 0; i < count; ++i) {
    Sim3Correspondence c;
    const Eigen::Vector3d p = random_point(1.0);
    const bool outlier = unit(random) < outlier_fraction;
    const Eigen::Vector3d q =
        outlier ? random_point(candidate_from_current.scale) : candidate_from_current * p;
    c.pixel_in_current = Project(camera, p) + noise2(0.5);
    c.pixel_in_candidate = Project(camera, q) + noise2(0.5);
    c.p_in_current = p * (1.0 + 0.01 * normal(random));
    c.p_in_candidate = q * (1.0 + 0.01 * normal(random));
    scene.correspondences.push_back(c);
    scene.is_outlier.push_back(outlier);
  }
  return scene;
}

const Sim3 kTruth(1.7,
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.2,
                                                       Eigen::Vector3d(0.3, 1, 0.1).normalized())),
                  Eigen::Vector3d(0.4, -0.1, 0.3));

void ExpectClassification(const Scene& scene, const Sim3SolverResult& result) {
  int true_inliers = 0, kept_inliers = 0, accepted_outliers = 0, outliers = 0;
  for (std::size_t i = 0; i < scene.is_outlier.size(); ++i) {
    if (scene.is_outlier[i]) {
      ++outliers;
      accepted_outliers += result.inliers[i] ? 1 : 0;
    } else {
      ++true_inliers;
      kept_inliers += result.inliers[i] ? 1 : 0;
    }
  }
  EXPECT_GE(kept_inliers, 0.95 * true_inliers);
  EXPECT_LE(accepted_outliers, 0.02 * outliers + 1);
}

TEST(Sim3SolverTest, RecoversASimilarityWithFortyPercentOutliers) {
  const Scene scene = MakeScene(kTruth, 300, 0.4, 3);
  const Sim3SolverResult result = SolveSim3(MakeCamera(), MakeCamera(), scene.correspondences);
  ASSERT_TRUE(result.success) << result.message;
  const Sim3& s = result.candidate_from_current;
  EXPECT_NEAR(s.scale, kTruth.scale, 0.01 * kTruth.scale);
  EXPECT_LT(RotationAngle(s.rotation.conjugate() * kTruth.rotation), 0.005);
  EXPECT_LT((s.translation - kTruth.translation).norm(), 0.03);
  EXPECT_LT(result.inlier_rms_px, 1.0);  // pixel noise is 0.5 px per axis
  ExpectClassification(scene, result);
}

TEST(Sim3SolverTest, RefinementLowersTheReprojectionError) {
  const Scene scene = MakeScene(kTruth, 300, 0.4, 5);
  Sim3SolverOptions no_refine;
  no_refine.refine_iterations = 0;
  const Sim3SolverResult raw =
      SolveSim3(MakeCamera(), MakeCamera(), scene.correspondences, no_refine);
  const Sim3SolverResult refined = SolveSim3(MakeCamera(), MakeCamera(), scene.correspondences);
  ASSERT_TRUE(raw.success && refined.success);
  // Compare on the same (refined) inlier set.
  double raw_sum = 0.0, refined_sum = 0.0;
  for (std::size_t i = 0; i < scene.correspondences.size(); ++i) {
    if (!refined.inliers[i] || !raw.inliers[i]) continue;
    raw_sum += Sim3ChiSquares(MakeCamera(), MakeCamera(), scene.correspondences[i],
                              raw.candidate_from_current)
                   .sum();
    refined_sum += Sim3ChiSquares(MakeCamera(), MakeCamera(), scene.correspondences[i],
                                  refined.candidate_from_current)
                       .sum();
  }
  EXPECT_LT(refined_sum, raw_sum);
}

TEST(Sim3SolverTest, FixedScaleKeepsScaleOneAndRecoversARigidTransform) {
  const Sim3 rigid(1.0, kTruth.rotation, kTruth.translation);
  const Scene scene = MakeScene(rigid, 200, 0.4, 7);
  Sim3SolverOptions options;
  options.fix_scale = true;
  const Sim3SolverResult result =
      SolveSim3(MakeCamera(), MakeCamera(), scene.correspondences, options);
  ASSERT_TRUE(result.success) << result.message;
  EXPECT_EQ(result.candidate_from_current.scale, 1.0);
  EXPECT_LT(RotationAngle(result.candidate_from_current.rotation.conjugate() * rigid.rotation),
            0.005);
  EXPECT_LT((result.candidate_from_current.translation - rigid.translation).norm(), 0.02);
  ExpectClassification(scene, result);
}

TEST(Sim3SolverTest, FixedScaleRejectsAScaledLoop) {
  // The map drifted in scale by 1.7: a rigid transform cannot explain the matches.
  const Scene scene = MakeScene(kTruth, 200, 0.0, 9);
  Sim3SolverOptions options;
  options.fix_scale = true;
  options.min_inliers = 100;
  EXPECT_FALSE(SolveSim3(MakeCamera(), MakeCamera(), scene.correspondences, options).success);
}

TEST(Sim3SolverTest, ZeroBaselineKeepsTheScaleOfThePoints) {
  // The loop keyframe was taken from the same place (no translation between the cameras):
  // the reprojection errors no longer depend on the scale, only the 3D points fix it.
  for (const double scale : {1.0, 0.6, 1.8}) {
    const Sim3 truth(scale, kTruth.rotation, Eigen::Vector3d::Zero());
    const Scene scene = MakeScene(truth, 200, 0.3, 17);
    Sim3SolverOptions options;
    options.refine_iterations = 100;  // room to drift along the unobservable scale
    const Sim3SolverResult result =
        SolveSim3(MakeCamera(), MakeCamera(), scene.correspondences, options);
    ASSERT_TRUE(result.success) << result.message;
    EXPECT_NEAR(result.candidate_from_current.scale, scale, 0.01 * scale);  // 3% off unfixed
    EXPECT_LT(result.candidate_from_current.translation.norm(), 0.05 * scale);
    ExpectClassification(scene, result);
  }
}

TEST(Sim3SolverTest, RejectsAnImplausibleScale) {
  // Matches consistent with a collapse of the current map by 50: no loop does that.
  const Sim3 collapse(0.02, kTruth.rotation, Eigen::Vector3d(0.01, 0.0, 0.0));
  const Scene scene = MakeScene(collapse, 200, 0.0, 19);
  const Sim3SolverResult result = SolveSim3(MakeCamera(), MakeCamera(), scene.correspondences);
  EXPECT_FALSE(result.success);
  EXPECT_NE(result.message.find("scale"), std::string::npos) << result.message;
}

TEST(Sim3SolverTest, FailsOnRandomMatches) {
  const Scene scene = MakeScene(kTruth, 200, 1.0, 11);
  const Sim3SolverResult result = SolveSim3(MakeCamera(), MakeCamera(), scene.correspondences);
  EXPECT_FALSE(result.success);
  EXPECT_LT(result.num_inliers, 20);
}

TEST(Sim3SolverTest, RejectsTooFewMatchesAndBadOptions) {
  const Scene scene = MakeScene(kTruth, 10, 0.0, 13);
  EXPECT_FALSE(SolveSim3(MakeCamera(), MakeCamera(), scene.correspondences).success);
  Sim3SolverOptions options;
  options.confidence = 1.0;
  EXPECT_FALSE(options.Check());
}

}  // namespace

}  // namespace arucoslam
