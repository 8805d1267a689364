#include "arucoslam/optim/marker_corner_error.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

const PinholeIntrinsics kIntrinsics{500.0, 490.0, 320.0, 240.0};

std::array<Eigen::Vector3d, 4> Square(double size) {
  const double h = size / 2;
  return {Eigen::Vector3d(-h, h, 0), Eigen::Vector3d(h, h, 0), Eigen::Vector3d(h, -h, 0),
          Eigen::Vector3d(-h, -h, 0)};
}

// A camera 2 m in front of a marker on a wall, both off-axis.
struct Scene {
  Rigid3 cam_from_world;
  Rigid3 world_from_marker;
  Scene() {
    Vector6d cam_tangent;
    cam_tangent << 0.1, -0.2, 0.3, 0.05, -0.1, 0.02;
    cam_from_world = Rigid3::Exp(cam_tangent);
    // Marker facing the camera: z out of the face, towards -z of the camera.
    const Rigid3 cam_from_marker(
        Eigen::Quaterniond(Eigen::AngleAxisd(M_PI + 0.3, Eigen::Vector3d::UnitY())) *
            Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX())),
        Eigen::Vector3d(0.2, -0.1, 2.0));
    world_from_marker = cam_from_world.Inverse() * cam_from_marker;
  }
};

std::array<Eigen::Vector2d, 4> Project(const Scene& s, const std::array<Eigen::Vector3d, 4>& c) {
  std::array<Eigen::Vector2d, 4> pixels;
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d p = s.cam_from_world * (s.world_from_marker * c[i]);
    pixels[i] = kIntrinsics.ToPixel(p.hnormalized());
  }
  return pixels;
}

TEST(MarkerCornerErrorTest, ZeroAtTruthAndPixelOffsetsOtherwise) {
  const Scene s;
  const auto corners = Square(0.3);
  auto observed = Project(s, corners);
  Vector8d residual;
  ASSERT_TRUE(MarkerCornerError(kIntrinsics, corners, observed)
                  .Evaluate(s.cam_from_world, s.world_from_marker, &residual));
  EXPECT_LT(residual.norm(), 1e-9);
  observed[2] += Eigen::Vector2d(1.5, -2.0);
  ASSERT_TRUE(MarkerCornerError(kIntrinsics, corners, observed)
                  .Evaluate(s.cam_from_world, s.world_from_marker, &residual));
  EXPECT_NEAR(residual[4], -1.5, 1e-9);
  EXPECT_NEAR(residual[5], 2.0, 1e-9);
  EXPECT_NEAR(residual.norm(), 2.5, 1e-9);
}

TEST(MarkerCornerErrorTest, JacobiansMatchNumericDifferences) {
  const Scene s;
  const auto corners = Square(0.25);
  auto observed = Project(s, corners);
  for (auto& pixel : observed) pixel += Eigen::Vector2d(3.0, -2.0);  // away from the optimum
  const MarkerCornerError error(kIntrinsics, corners, observed);
  Vector8d residual;
  MarkerCornerJacobian d_cam, d_marker;
  ASSERT_TRUE(error.Evaluate(s.cam_from_world, s.world_from_marker, &residual, &d_cam, &d_marker));
  const double h = 1e-6;
  MarkerCornerJacobian numeric_cam, numeric_marker;
  for (int k = 0; k < 6; ++k) {
    Vector6d delta = Vector6d::Zero();
    delta[k] = h;
    Vector8d plus, minus;
    ASSERT_TRUE(error.Evaluate(Rigid3::Exp(delta) * s.cam_from_world, s.world_from_marker, &plus));
    ASSERT_TRUE(
        error.Evaluate(Rigid3::Exp(-delta) * s.cam_from_world, s.world_from_marker, &minus));
    numeric_cam.col(k) = (plus - minus) / (2 * h);
    ASSERT_TRUE(error.Evaluate(s.cam_from_world, Rigid3::Exp(delta) * s.world_from_marker, &plus));
    ASSERT_TRUE(
        error.Evaluate(s.cam_from_world, Rigid3::Exp(-delta) * s.world_from_marker, &minus));
    numeric_marker.col(k) = (plus - minus) / (2 * h);
  }
  // Entries are hundreds of pixels per unit; central differences agree to ~1e-6 relative.
  EXPECT_LT((d_cam - numeric_cam).cwiseAbs().maxCoeff(), 1e-4 * d_cam.cwiseAbs().maxCoeff());
  EXPECT_LT((d_marker - numeric_marker).cwiseAbs().maxCoeff(),
            1e-4 * d_marker.cwiseAbs().maxCoeff());
  EXPECT_GT(d_marker.cwiseAbs().maxCoeff(), 10.0);  // not trivially zero
}

TEST(MarkerCornerErrorTest, MarkerBehindTheCameraIsRejected) {
  Scene s;
  const auto corners = Square(0.3);
  const auto observed = Project(s, corners);
  const Rigid3 turned(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY())),
                      Eigen::Vector3d::Zero());
  Vector8d residual = Vector8d::Constant(7.0);
  EXPECT_FALSE(MarkerCornerError(kIntrinsics, corners, observed)
                   .Evaluate(turned * s.cam_from_world, s.world_from_marker, &residual));
  EXPECT_EQ(residual, Vector8d::Constant(7.0));
}

TEST(MarkerCornerErrorTest, UndistortedCornersInvertTheDistortion) {
  CameraModel camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = 500;
  camera.fy = 500;
  camera.cx = 320;
  camera.cy = 240;
  camera.model = DistortionModel::kRadTan;
  camera.distortion = {-0.28, 0.07, 0.0002, 0.00002, 0.0};
  std::array<Eigen::Vector2d, 4> undistorted_truth = {
      Eigen::Vector2d(100, 80), Eigen::Vector2d(200, 85), Eigen::Vector2d(205, 190),
      Eigen::Vector2d(95, 185)};
  std::array<Eigen::Vector2d, 4> distorted;
  const PinholeIntrinsics k = PinholeIntrinsics::FromCamera(camera);
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d normalised((undistorted_truth[i].x() - k.cx) / k.fx,
                                     (undistorted_truth[i].y() - k.cy) / k.fy);
    distorted[i] = camera.Distort(normalised);
    EXPECT_GT((distorted[i] - undistorted_truth[i]).norm(), 1.0);  // distortion matters here
  }
  const auto undistorted = UndistortedCorners(camera, distorted);
  for (int i = 0; i < 4; ++i) EXPECT_LT((undistorted[i] - undistorted_truth[i]).norm(), 1e-6);
}

}  // namespace
}  // namespace arucoslam
