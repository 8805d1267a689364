#include "arucoslam/optim/marker_location_information.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <random>

#include "arucoslam/markers/marker_pose.h"

namespace arucoslam {
namespace {

const PinholeIntrinsics kIntrinsics{460.0, 455.0, 320.0, 240.0};

// A marker of side `size` facing a camera at the world origin (looking down +z), `distance`
// metres ahead and `lateral` metres to the side, turned 25 degrees about its vertical.
MarkerPoseObservation MarkerAhead(double size, double distance, double lateral) {
  MarkerPoseObservation marker;
  marker.size = size;
  marker.world_from_marker =
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI + 0.45, Eigen::Vector3d::UnitY())),
             Eigen::Vector3d(lateral, 0.1, distance));
  return marker;
}

// Corners of `marker` seen from `world_from_cam`, in undistorted pixels.
std::array<Eigen::Vector2d, 4> Seen(const MarkerPoseObservation& marker,
                                    const Rigid3& world_from_cam) {
  const Rigid3 cam_from_marker = world_from_cam.Inverse() * marker.world_from_marker;
  std::array<Eigen::Vector2d, 4> pixels;
  const std::array<Eigen::Vector3d, 4> corners = SquareCorners(marker.size);
  for (int i = 0; i < 4; ++i) {
    pixels[i] = kIntrinsics.ToPixel((cam_from_marker * corners[i]).hnormalized());
  }
  return pixels;
}

// PosePriorError's perturbation of a camera pose: centre + d_centre, rotation * Exp(d_rotation).
Rigid3 Perturbed(const Rigid3& world_from_cam, const Vector6d& delta) {
  return Rigid3(world_from_cam.rotation * ExpSO3(delta.tail<3>()),
                world_from_cam.translation + delta.head<3>());
}

std::vector<MarkerPoseObservation> TwoMarkers(const Rigid3& world_from_cam) {
  std::vector<MarkerPoseObservation> markers = {MarkerAhead(0.2, 2.5, -0.4),
                                                MarkerAhead(0.15, 3.5, 0.6)};
  for (MarkerPoseObservation& marker : markers) {
    marker.corners_px = Seen(marker, world_from_cam);
    marker.sigma_px = 0.8;
  }
  return markers;
}

TEST(MarkerLocationInformation, IsJacobianTransposeJacobianOverSigmaSquaredOfTheCornerPixels) {
  const Rigid3 world_from_cam(ExpSO3(Eigen::Vector3d(0.02, -0.05, 0.01)),
                              Eigen::Vector3d(0.05, -0.02, 0.1));
  const std::vector<MarkerPoseObservation> markers = TwoMarkers(world_from_cam);
  Eigen::Matrix<double, 16, 6> numeric;
  const double step = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Vector6d delta = Vector6d::Zero();
    delta(k) = step;
    for (std::size_t m = 0; m < markers.size(); ++m) {
      const auto plus = Seen(markers[m], Perturbed(world_from_cam, delta));
      const auto minus = Seen(markers[m], Perturbed(world_from_cam, -delta));
      for (int i = 0; i < 4; ++i) {
        numeric.block<2, 1>(8 * m + 2 * i, k) = (plus[i] - minus[i]) / (2 * step);
      }
    }
  }
  const Matrix6d expected = numeric.transpose() * numeric / (0.8 * 0.8);
  const Matrix6d information = MarkerLocationInformation(world_from_cam, markers, kIntrinsics);
  EXPECT_LT((information - expected).norm(), 1e-5 * expected.norm());
}

TEST(MarkerLocationInformation, PredictsTheScatterOfPosesFromNoisyCorners) {
  const Rigid3 truth(ExpSO3(Eigen::Vector3d(0.0, 0.1, 0.0)), Eigen::Vector3d::Zero());
  std::vector<MarkerPoseObservation> markers = {MarkerAhead(0.2, 3.0, 0.3)};
  markers[0].corners_px = Seen(markers[0], truth);
  const Matrix6d information = MarkerLocationInformation(truth, markers, kIntrinsics);
  std::mt19937 random(7);
  std::normal_distribution<double> pixel_noise(0.0, 1.0);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  const int samples = 400;
  for (int n = 0; n < samples; ++n) {
    std::vector<MarkerPoseObservation> noisy = markers;
    for (Eigen::Vector2d& corner : noisy[0].corners_px) {
      corner += Eigen::Vector2d(pixel_noise(random), pixel_noise(random));
    }
    const MarkerPoseOptimizationResult result =
        OptimizePoseWithMarkers({}, noisy, truth.Inverse(), kIntrinsics);
    ASSERT_TRUE(result.success);
    const Eigen::Vector3d error = result.cam_from_world.Inverse().translation;
    scatter += error * error.transpose() / samples;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter, Eigen::EigenvaluesOnly);
  const double measured = std::sqrt(eigen.eigenvalues()(2));
  EXPECT_NEAR(LeastCertainPositionSigma(information) / measured, 1.0, 0.15);
}

TEST(MarkerLocationInformation, CentreSigmaGrowsWithTheSquareOfTheDistance) {
  const Rigid3 world_from_cam;
  double sigma[2];
  for (int k = 0; k < 2; ++k) {
    std::vector<MarkerPoseObservation> markers = {MarkerAhead(0.2, 2.0 * (k + 1), 0.0)};
    markers[0].corners_px = Seen(markers[0], world_from_cam);
    sigma[k] =
        LeastCertainPositionSigma(MarkerLocationInformation(world_from_cam, markers, kIntrinsics));
  }
  EXPECT_NEAR(sigma[1] / sigma[0], 4.0, 0.6);
}

TEST(MarkerLocationInformation, NothingSeenInFrontGivesNoInformation) {
  std::vector<MarkerPoseObservation> markers = {MarkerAhead(0.2, 2.0, 0.0)};
  markers[0].corners_px = Seen(markers[0], Rigid3());
  const Rigid3 turned_away(ExpSO3(Eigen::Vector3d(0.0, M_PI, 0.0)), Eigen::Vector3d::Zero());
  EXPECT_EQ(MarkerLocationInformation(turned_away, markers, kIntrinsics).norm(), 0.0);
  EXPECT_EQ(MarkerLocationInformation(Rigid3(), {}, kIntrinsics).norm(), 0.0);
}

}  // namespace
}  // namespace arucoslam
