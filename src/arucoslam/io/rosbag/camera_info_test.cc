#include "arucoslam/io/rosbag/camera_info.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

CameraModel RadTanCamera() {
  CameraModel camera = PinholeCamera(640, 480, 458.654);
  camera.fy = 457.296;
  camera.cx = 367.215;
  camera.cy = 248.375;
  camera.model = DistortionModel::kRadTan;
  camera.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0};
  return camera;
}

TEST(CameraInfoTest, PlumbBobRoundTripsExactly) {
  const CameraModel camera = RadTanCamera();
  const sensor_msgs::CameraInfo info = CameraInfoFromModel(camera);
  EXPECT_EQ(info.distortion_model, "plumb_bob");
  const CameraModel back = CameraFromInfo(info, "t");
  EXPECT_EQ(back.width, 640);
  EXPECT_EQ(back.height, 480);
  EXPECT_EQ(back.fx, camera.fx);
  EXPECT_EQ(back.fy, camera.fy);
  EXPECT_EQ(back.cx, camera.cx);
  EXPECT_EQ(back.cy, camera.cy);
  EXPECT_EQ(back.model, DistortionModel::kRadTan);
  EXPECT_EQ(back.distortion, camera.distortion);
}

TEST(CameraInfoTest, EquidistantAndDistortionFree) {
  CameraModel fisheye = RadTanCamera();
  fisheye.model = DistortionModel::kEquidistant;
  fisheye.distortion = {0.01, -0.002, 0.0003, -0.00004, 0.0};
  const CameraModel back = CameraFromInfo(CameraInfoFromModel(fisheye), "t");
  EXPECT_EQ(back.model, DistortionModel::kEquidistant);
  EXPECT_EQ(back.distortion, fisheye.distortion);

  sensor_msgs::CameraInfo info = CameraInfoFromModel(PinholeCamera(320, 240, 200.0));
  EXPECT_EQ(CameraFromInfo(info, "t").model, DistortionModel::kNone);  // zero coefficients
  info.D.clear();  // drivers of distortion-free cameras publish an empty D
  EXPECT_EQ(CameraFromInfo(info, "t").model, DistortionModel::kNone);
}

TEST(CameraInfoTest, RationalPolynomialRoundTripsExactly) {
  CameraModel camera = RadTanCamera();
  camera.model = DistortionModel::kRational;
  camera.distortion = {};
  const std::array<double, 8> rational = {0.16443, -0.98662, 0.003473, -0.002772,
                                          1.89095, 0.04109,  0.06374,  -0.06795};
  std::copy(rational.begin(), rational.end(), camera.distortion.begin());
  const sensor_msgs::CameraInfo info = CameraInfoFromModel(camera);
  EXPECT_EQ(info.distortion_model, "rational_polynomial");
  EXPECT_EQ(info.D.size(), 8u);
  const CameraModel back = CameraFromInfo(info, "t");
  EXPECT_EQ(back.model, DistortionModel::kRational);
  EXPECT_EQ(back.distortion, camera.distortion);
}

TEST(CameraInfoTest, RefusalsNameTheSourceAndField) {
  sensor_msgs::CameraInfo info = CameraInfoFromModel(RadTanCamera());
  info.distortion_model = "division";
  try {
    CameraFromInfo(info, "x.bag: /cam/camera_info");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "x.bag: /cam/camera_info");
    EXPECT_NE(error.message().find("division"), std::string::npos) << error.what();
  }
  info = CameraInfoFromModel(RadTanCamera());
  info.K = {};  // an uncalibrated camera publishes K = 0
  EXPECT_THROW(CameraFromInfo(info, "t"), InputError);
  info = CameraInfoFromModel(RadTanCamera());
  info.width = 0;
  EXPECT_THROW(CameraFromInfo(info, "t"), InputError);
}

}  // namespace
}  // namespace arucoslam
