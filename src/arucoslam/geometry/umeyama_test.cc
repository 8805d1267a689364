#include "arucoslam/geometry/umeyama.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace arucoslam {
namespace {

const Sim3 kTruth(2.5,
                  Eigen::Quaterniond(Eigen::AngleAxisd(2.2,
                                                       Eigen::Vector3d(1, -2, 0.5).normalized())),
                  Eigen::Vector3d(4.0, -1.0, 0.75));

std::vector<Eigen::Vector3d> RandomPoints(int count, double half_extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-half_extent, half_extent);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) points.emplace_back(uniform(rng), uniform(rng), uniform(rng));
  return points;
}

std::vector<Eigen::Vector3d> Transform(const Sim3& target_from_source,
                                       const std::vector<Eigen::Vector3d>& source,
                                       double noise_sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_sigma);
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) {
    target.push_back(target_from_source * p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  }
  return target;
}

double SumSquaredResiduals(const Sim3& target_from_source,
                           const std::vector<Eigen::Vector3d>& source,
                           const std::vector<Eigen::Vector3d>& target) {
  double sum = 0.0;
  for (std::size_t i = 0; i < source.size(); ++i) {
    sum += (target[i] - target_from_source * source[i]).squaredNorm();
  }
  return sum;
}

double RotationError(const Sim3& a, const Sim3& b) {
  return RotationAngle(a.rotation.conjugate() * b.rotation);
}

TEST(UmeyamaTest, RecoversASimilarityFromExactPoints) {
  const auto source = RandomPoints(20, 5.0, 1);
  const auto fit =
      UmeyamaAlignment(source, Transform(kTruth, source, 0.0, 0), AlignmentKind::kSimilarity);
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->scale, kTruth.scale, 1e-12);
  EXPECT_LT(RotationError(*fit, kTruth), 1e-12);
  EXPECT_LT((fit->translation - kTruth.translation).norm(), 1e-11);
}

TEST(UmeyamaTest, RecoversARigidTransformWithScaleExactlyOne) {
  const Sim3 rigid_truth(1.0, kTruth.rotation, kTruth.translation);
  const auto source = RandomPoints(3, 5.0, 2);  // the minimum
  const auto fit =
      UmeyamaAlignment(source, Transform(rigid_truth, source, 0.0, 0), AlignmentKind::kRigid);
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(fit->scale, 1.0);
  EXPECT_LT(RotationError(*fit, rigid_truth), 1e-12);
  EXPECT_LT((fit->translation - rigid_truth.translation).norm(), 1e-11);
}

// With kRigid, data that really differ by a scale still give scale 1 (not estimated).
TEST(UmeyamaTest, RigidKindDoesNotEstimateScale) {
  const auto source = RandomPoints(30, 5.0, 3);
  const auto fit =
      UmeyamaAlignment(source, Transform(kTruth, source, 0.0, 0), AlignmentKind::kRigid);
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(fit->scale, 1.0);
  // The rotation is still right (it does not depend on the scale).
  EXPECT_LT(RotationError(*fit, kTruth), 1e-12);
}

// 200 points in a 10 m cube with 1 cm Gaussian noise: the expected errors are about
// 0.01 / sqrt(200) / 3 m ~ 2e-4 rad, scale ~ 1e-4; bounds are five times that.
TEST(UmeyamaTest, NoisyPointsGiveTheLeastSquaresFitNearTheTruth) {
  const auto source = RandomPoints(200, 5.0, 4);
  for (const AlignmentKind kind : {AlignmentKind::kSimilarity, AlignmentKind::kRigid}) {
    const Sim3 truth =
        kind == AlignmentKind::kRigid ? Sim3(1.0, kTruth.rotation, kTruth.translation) : kTruth;
    const auto noisy_target = Transform(truth, source, 0.01, 5);
    const auto fit = UmeyamaAlignment(source, noisy_target, kind);
    ASSERT_TRUE(fit.has_value());
    EXPECT_LT(RotationError(*fit, truth), 1e-3);
    EXPECT_NEAR(fit->scale, truth.scale, 1e-3 * truth.scale);
    EXPECT_LT((fit->translation - truth.translation).norm(), 5e-3);
    // Least squares: no worse than the true transform, and the residual is the noise.
    const double fit_sum = SumSquaredResiduals(*fit, source, noisy_target);
    EXPECT_LE(fit_sum, SumSquaredResiduals(truth, source, noisy_target));
    EXPECT_NEAR(std::sqrt(fit_sum / (3.0 * source.size())), 0.01, 0.002);
    // Small perturbations of the fit only increase the residual.
    for (int k = 0; k < 7; ++k) {
      Vector7d delta = Vector7d::Zero();
      delta(k) = 1e-4;
      if (kind == AlignmentKind::kRigid && k == 6) continue;
      EXPECT_GT(SumSquaredResiduals(Sim3::Exp(delta) * *fit, source, noisy_target), fit_sum);
      EXPECT_GT(SumSquaredResiduals(Sim3::Exp(-delta) * *fit, source, noisy_target), fit_sum);
    }
  }
}

// A mirrored target must still give a proper rotation (det +1), never a reflection.
TEST(UmeyamaTest, MirroredTargetStillGivesARotation) {
  const auto source = RandomPoints(10, 2.0, 6);
  std::vector<Eigen::Vector3d> mirrored;
  for (const auto& p : source) mirrored.emplace_back(p.x(), p.y(), -p.z());
  const auto fit = UmeyamaAlignment(source, mirrored, AlignmentKind::kSimilarity);
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->rotation.toRotationMatrix().determinant(), 1.0, 1e-12);
  EXPECT_GT(fit->scale, 0.0);
}

TEST(UmeyamaTest, CollinearPointsFitExactly) {
  std::vector<Eigen::Vector3d> source;
  for (int i = 0; i < 10; ++i)
    source.push_back(Eigen::Vector3d(1.0, 2.0, 3.0) + i * Eigen::Vector3d(0.3, -0.1, 0.2));
  const auto target = Transform(kTruth, source, 0.0, 0);
  const auto fit = UmeyamaAlignment(source, target, AlignmentKind::kSimilarity);
  ASSERT_TRUE(fit.has_value());
  EXPECT_NEAR(fit->scale, kTruth.scale, 1e-12);
  EXPECT_LT(SumSquaredResiduals(*fit, source, target), 1e-20);
}

TEST(UmeyamaTest, RejectsDegenerateInput) {
  const auto source = RandomPoints(10, 2.0, 7);
  const auto target = Transform(kTruth, source, 0.0, 0);
  const std::vector<Eigen::Vector3d> two_source(source.begin(), source.begin() + 2);
  const std::vector<Eigen::Vector3d> two_target(target.begin(), target.begin() + 2);
  EXPECT_FALSE(UmeyamaAlignment(two_source, two_target, AlignmentKind::kSimilarity));
  EXPECT_FALSE(UmeyamaAlignment({}, {}, AlignmentKind::kRigid));
  const std::vector<Eigen::Vector3d> fewer_targets(target.begin(), target.end() - 1);
  EXPECT_FALSE(UmeyamaAlignment(source, fewer_targets, AlignmentKind::kSimilarity));
  const std::vector<Eigen::Vector3d> coincident(10, Eigen::Vector3d(1.0, 1.0, 1.0));
  EXPECT_FALSE(UmeyamaAlignment(coincident, target, AlignmentKind::kSimilarity));
  EXPECT_FALSE(UmeyamaAlignment(coincident, target, AlignmentKind::kRigid));
  // A target collapsed to one point has no similarity onto it; a rigid fit moves the
  // centroid there.
  EXPECT_FALSE(UmeyamaAlignment(source, coincident, AlignmentKind::kSimilarity));
  const auto rigid = UmeyamaAlignment(source, coincident, AlignmentKind::kRigid);
  ASSERT_TRUE(rigid.has_value());
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : source) centroid += p / 10.0;
  EXPECT_TRUE((*rigid * centroid).isApprox(Eigen::Vector3d(1.0, 1.0, 1.0), 1e-12));
}

}  // namespace
}  // namespace arucoslam
