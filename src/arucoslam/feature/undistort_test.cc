#include "arucoslam/feature/undistort.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

namespace arucoslam {
namespace {

TEST(UndistortFeatures, AgreesWithOpenCvOnTheEurocCamera) {
  CameraModel camera;  // cam0 of EuRoC V1_01 (euroc_v101_micro/README.md)
  camera.width = 752;
  camera.height = 480;
  camera.fx = 458.654;
  camera.fy = 457.296;
  camera.cx = 367.215;
  camera.cy = 248.375;
  camera.model = DistortionModel::kRadTan;
  camera.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0};
  OrbFeatures features;
  std::vector<cv::Point2f> pixels;
  for (int y = 20; y < 480; y += 40) {
    for (int x = 20; x < 752; x += 40) {
      features.keypoints.emplace_back(static_cast<float>(x), static_cast<float>(y), 31.0f);
      pixels.emplace_back(static_cast<float>(x), static_cast<float>(y));
    }
  }
  UndistortFeatures(camera, &features);
  ASSERT_EQ(features.undistorted.size(), features.keypoints.size());
  const cv::Matx33d k(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  const std::vector<double> d = {camera.distortion[0], camera.distortion[1], camera.distortion[2],
                                 camera.distortion[3], 0.0};
  std::vector<cv::Point2f> expected;
  cv::undistortPoints(pixels, expected, k, d, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT, 100, 0));
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    // Within 0.01 px (in pixel units at the focal length) of OpenCV, and exact round trip.
    EXPECT_NEAR(features.undistorted[i].x(), expected[i].x, 0.01 / camera.fx) << pixels[i];
    EXPECT_NEAR(features.undistorted[i].y(), expected[i].y, 0.01 / camera.fy) << pixels[i];
    const Eigen::Vector2d back = camera.Distort(features.undistorted[i]);
    EXPECT_NEAR(back.x(), pixels[i].x, 1e-6);
    EXPECT_NEAR(back.y(), pixels[i].y, 1e-6);
  }
}

}  // namespace
}  // namespace arucoslam
