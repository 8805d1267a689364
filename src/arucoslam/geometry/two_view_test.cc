#include "arucoslam/geometry/two_view.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arucoslam {
namespace {

Eigen::Matrix3d TestK() {
  Eigen::Matrix3d k;
  k << 500.0, 0.0, 320.0, 0.0, 505.0, 240.0, 0.0, 0.0, 1.0;
  return k;
}

Eigen::Vector2d ToPixel(const Eigen::Matrix3d& k, const Eigen::Vector3d& p_in_cam) {
  return (k * p_in_cam).hnormalized();
}

// Rotation angle (radians) of a * b^T.
double RotationDistance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return RotationAngle(Eigen::Quaterniond(a * b.transpose()));
}

// Matrices equal up to a non-zero scale (including sign).
double ProjectiveDistance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const Eigen::Matrix3d na = a / a.norm(), nb = b / b.norm();
  return std::min((na - nb).norm(), (na + nb).norm());
}

struct Scene {
  Rigid3 cam2_from_cam1;
  std::vector<Eigen::Vector3d> points_in_cam1;
  Point2dList pixels1, pixels2;
};

// Random points in front of camera 1 (depth 2..8 m) seen by both cameras, pixel noise sigma.
Scene MakeScene(const Rigid3& cam2_from_cam1, int count, double noise_px, std::uint32_t seed,
                bool planar = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  const Eigen::Matrix3d k = TestK();
  Scene scene;
  scene.cam2_from_cam1 = cam2_from_cam1;
  while (static_cast<int>(scene.points_in_cam1.size()) < count) {
    Eigen::Vector3d p;
    if (planar) {  // plane z = 4 + 0.3 x (tilted)
      p.x() = 3.0 * unit(rng);
      p.y() = 2.0 * unit(rng);
      p.z() = 4.0 + 0.3 * p.x();
    } else {
      const double depth = 5.0 + 3.0 * unit(rng);
      p = Eigen::Vector3d(0.6 * depth * unit(rng), 0.45 * depth * unit(rng), depth);
    }
    const Eigen::Vector3d q = cam2_from_cam1 * p;
    if (q.z() <= 0.5) continue;
    const Eigen::Vector2d a = ToPixel(k, p), b = ToPixel(k, q);
    if (a.x() < 0 || a.x() > 639 || a.y() < 0 || a.y() > 479) continue;
    if (b.x() < 0 || b.x() > 639 || b.y() < 0 || b.y() > 479) continue;
    scene.points_in_cam1.push_back(p);
    scene.pixels1.push_back(a + Eigen::Vector2d(noise(rng), noise(rng)));
    scene.pixels2.push_back(b + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  return scene;
}

// Per-image noise such that a transfer residual (which carries the noise of both images) has
// a standard deviation of 1 px, the sigma the RANSAC gates assume by default.
const double kNoisePx = 1.0 / std::sqrt(2.0);

Rigid3 GeneralMotion() {
  return Rigid3(ExpSO3(Eigen::Vector3d(0.02, -0.08, 0.03)), Eigen::Vector3d(-0.4, 0.05, 0.1));
}

Eigen::Matrix3d TrueFundamental(const Rigid3& motion) {
  const Eigen::Matrix3d k_inv = TestK().inverse();
  return k_inv.transpose() * Hat(motion.translation) * motion.RotationMatrix() * k_inv;
}

TEST(TwoView, FundamentalFromExactPoints) {
  const Rigid3 motion = GeneralMotion();
  const Eigen::Matrix3d truth = TrueFundamental(motion);
  for (int count : {8, 100}) {
    const Scene scene = MakeScene(motion, count, 0.0, 1);
    const Eigen::Matrix3d f = FundamentalFromPoints(scene.pixels1, scene.pixels2);
    EXPECT_LT(ProjectiveDistance(f, truth), 1e-6) << count << " points";
    EXPECT_NEAR(f.determinant(), 0.0, 1e-12);
  }
  EXPECT_TRUE(FundamentalFromPoints(Point2dList(7, Eigen::Vector2d::Zero()),
                                    Point2dList(7, Eigen::Vector2d::Zero()))
                  .isZero());
}

TEST(TwoView, HomographyFromExactPlanarPoints) {
  const Rigid3 motion = GeneralMotion();
  for (int count : {4, 100}) {
    const Scene scene = MakeScene(motion, count, 0.0, 2, /*planar=*/true);
    const Eigen::Matrix3d h = HomographyFromPoints(scene.pixels1, scene.pixels2);
    for (int i = 0; i < count; ++i) {
      EXPECT_LT(((h * scene.pixels1[i].homogeneous()).hnormalized() - scene.pixels2[i]).norm(),
                1e-6);
    }
    // The plane z = 4 + 0.3 x is n^T X = d with n = (-0.3, 0, 1) / |.|, d = 4 / |.|.
    const Eigen::Vector3d n = Eigen::Vector3d(-0.3, 0.0, 1.0);
    const Eigen::Matrix3d truth =
        TestK() * (motion.RotationMatrix() + motion.translation * n.transpose() / 4.0) *
        TestK().inverse();
    EXPECT_LT(ProjectiveDistance(h, truth), 1e-6);
  }
}

TEST(TwoView, FundamentalRansacSeparatesOutliers) {
  const Rigid3 motion = GeneralMotion();
  Scene scene = MakeScene(motion, 300, kNoisePx, 3);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> x(0.0, 639.0), y(0.0, 479.0);
  std::vector<bool> is_outlier(scene.pixels2.size(), false);
  for (std::size_t i = 0; i < scene.pixels2.size(); i += 3) {  // a third are outliers
    scene.pixels2[i] = Eigen::Vector2d(x(rng), y(rng));
    is_outlier[i] = true;
  }
  const TwoViewModel model = FindFundamentalRansac(scene.pixels1, scene.pixels2);
  ASSERT_TRUE(model.valid);
  int true_inliers = 0, kept_inliers = 0, outliers = 0, kept_outliers = 0;
  for (std::size_t i = 0; i < is_outlier.size(); ++i) {
    if (is_outlier[i]) {
      ++outliers;
      kept_outliers += model.inliers[i];
    } else {
      ++true_inliers;
      kept_inliers += model.inliers[i];
    }
  }
  // The 95% chi-square gates in both images keep at least 90% of the true inliers.
  EXPECT_GE(kept_inliers, 0.85 * true_inliers);
  EXPECT_LE(kept_outliers, 0.05 * outliers);
  EXPECT_LT(ProjectiveDistance(model.matrix, TrueFundamental(motion)), 0.05);
  // Same seed, same answer.
  const TwoViewModel again = FindFundamentalRansac(scene.pixels1, scene.pixels2);
  EXPECT_EQ(again.inliers, model.inliers);
  EXPECT_EQ(again.score, model.score);
}

TEST(TwoView, HomographyRansacOnPlane) {
  Scene scene = MakeScene(GeneralMotion(), 200, kNoisePx, 5, /*planar=*/true);
  const TwoViewModel model = FindHomographyRansac(scene.pixels1, scene.pixels2);
  ASSERT_TRUE(model.valid);
  EXPECT_GE(model.num_inliers, 0.85 * 200);
}

TEST(TwoView, ScoresPreferTheRightModel) {
  // A general scene is explained by F, not by H. On a plane both fit every point; per point
  // an H direction earns 5.991 - E[chi2(2)] ~ 4 and an F direction 5.991 - E[chi2(1)] ~ 5,
  // so the H share is about 4 / 9 = 0.44: a choice threshold of 0.40 separates the two.
  const Scene general = MakeScene(GeneralMotion(), 200, kNoisePx, 6);
  const double f_general = FindFundamentalRansac(general.pixels1, general.pixels2).score;
  const double h_general = FindHomographyRansac(general.pixels1, general.pixels2).score;
  RecordProperty("h_share_general", std::to_string(h_general / (h_general + f_general)));
  EXPECT_LT(h_general / (h_general + f_general), 0.3);
  const Scene plane = MakeScene(GeneralMotion(), 200, kNoisePx, 7, true);
  const double f_plane = FindFundamentalRansac(plane.pixels1, plane.pixels2).score;
  const double h_plane = FindHomographyRansac(plane.pixels1, plane.pixels2).score;
  RecordProperty("h_share_plane", std::to_string(h_plane / (h_plane + f_plane)));
  EXPECT_GT(h_plane / (h_plane + f_plane), 0.40);
}

TEST(TwoView, EssentialDecompositionContainsTheTruth) {
  const Rigid3 motion = GeneralMotion();
  const Scene scene = MakeScene(motion, 50, 0.0, 8);
  const Eigen::Matrix3d f = FundamentalFromPoints(scene.pixels1, scene.pixels2);
  const Eigen::Matrix3d e = EssentialFromFundamental(f, TestK(), TestK());
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(e);
  EXPECT_NEAR(svd.singularValues()(0), svd.singularValues()(1), 1e-12);
  EXPECT_NEAR(svd.singularValues()(2), 0.0, 1e-12);
  const std::array<Rigid3, 4> candidates = DecomposeEssential(e);
  int matching = 0;
  for (const Rigid3& c : candidates) {
    EXPECT_NEAR(c.RotationMatrix().determinant(), 1.0, 1e-9);
    if (RotationDistance(c.RotationMatrix(), motion.RotationMatrix()) < 1e-6 &&
        (c.translation - motion.translation.normalized()).norm() < 1e-6) {
      ++matching;
    }
  }
  EXPECT_EQ(matching, 1);
}

TEST(TwoView, HomographyDecompositionContainsTheTruth) {
  const Rigid3 motion = GeneralMotion();
  const Scene scene = MakeScene(motion, 60, 0.0, 9, true);
  const Eigen::Matrix3d h = HomographyFromPoints(scene.pixels1, scene.pixels2);
  // Scale and sign of H must not matter.
  for (const double scale : {1.0, -3.0}) {
    const std::vector<HomographyMotion> candidates =
        DecomposeHomography(scale * h, TestK(), TestK());
    ASSERT_EQ(candidates.size(), 8u);
    const Eigen::Vector3d n = Eigen::Vector3d(-0.3, 0.0, 1.0);
    const double d = 4.0 / n.norm();
    int matching = 0;
    for (const HomographyMotion& c : candidates) {
      EXPECT_NEAR(c.cam2_from_cam1.RotationMatrix().determinant(), 1.0, 1e-9);
      if (RotationDistance(c.cam2_from_cam1.RotationMatrix(), motion.RotationMatrix()) < 1e-6 &&
          (c.cam2_from_cam1.translation - motion.translation / d).norm() < 1e-6 &&
          (c.normal_in_cam1 - n.normalized()).norm() < 1e-6) {
        ++matching;
      }
    }
    EXPECT_EQ(matching, 1) << "scale " << scale;
  }
}

TEST(TwoView, HomographyOfPureRotationHasNoTranslationSolution) {
  const Eigen::Matrix3d rotation = ExpSO3(Eigen::Vector3d(0.05, 0.1, -0.02)).toRotationMatrix();
  const Eigen::Matrix3d h = TestK() * rotation * TestK().inverse();
  EXPECT_TRUE(DecomposeHomography(h, TestK(), TestK()).empty());
}

}  // namespace
}  // namespace arucoslam
