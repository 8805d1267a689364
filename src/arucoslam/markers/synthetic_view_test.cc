#include "arucoslam/markers/synthetic_view.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace arucoslam {
namespace {

SyntheticMarker FrontoParallel(double depth) {
  SyntheticMarker marker;
  marker.cam_from_marker = Rigid3(Eigen::Matrix3d(Eigen::Vector3d(1, -1, -1).asDiagonal()),
                                  Eigen::Vector3d(0, 0, depth));
  return marker;
}

TEST(SyntheticViewTest, BlackSquareLandsWhereProjected) {
  // A fronto-parallel 0.2 m marker at 1 m spans 100 px; without blur or noise the ink
  // edges must sit at the projected corners (columns 269.5 .. 369.5).
  SyntheticViewOptions options;
  options.background = SyntheticBackground::kUniform;
  options.blur_sigma_px = 0.0;
  options.noise_sigma = 0.0;
  const SyntheticMarker marker = FrontoParallel(1.0);
  const cv::Mat image = RenderSyntheticView(SyntheticCamera640(), {marker}, options);
  const auto corners = ProjectMarkerCorners(SyntheticCamera640(), marker);
  EXPECT_NEAR(corners[0].x(), 269.5, 1e-9);
  EXPECT_NEAR(corners[0].y(), 189.5, 1e-9);
  EXPECT_NEAR(corners[2].x(), 369.5, 1e-9);
  // Pixels just inside the black border are ink, just outside are paper (margin).
  EXPECT_NEAR(image.at<uint8_t>(240, 271), 25, 2);
  EXPECT_NEAR(image.at<uint8_t>(240, 268), 220, 2);
  EXPECT_NEAR(image.at<uint8_t>(240, 368), 25, 2);
  EXPECT_NEAR(image.at<uint8_t>(240, 371), 220, 2);
  // Far outside the marker: background level.
  EXPECT_EQ(image.at<uint8_t>(10, 10), 128);
}

TEST(SyntheticViewTest, NoiseAndTextureAreDeterministicAndSized) {
  SyntheticViewOptions options;
  options.seed = 7;
  const cv::Mat a = RenderSyntheticView(SyntheticCamera640(), {FrontoParallel(2.0)}, options);
  const cv::Mat b = RenderSyntheticView(SyntheticCamera640(), {FrontoParallel(2.0)}, options);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  options.seed = 8;
  const cv::Mat c = RenderSyntheticView(SyntheticCamera640(), {FrontoParallel(2.0)}, options);
  EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 10.0);
  // Texture standard deviation away from the marker is near what was asked for.
  cv::Scalar mean, stddev;
  cv::meanStdDev(a(cv::Rect(0, 0, 150, 480)), mean, stddev);
  EXPECT_NEAR(mean[0], 128.0, 25.0);
  EXPECT_GT(stddev[0], 20.0);
}

TEST(SyntheticViewTest, RejectsDistortedCameraAndBadOptions) {
  CameraModel camera = SyntheticCamera640();
  camera.model = DistortionModel::kRadTan;
  EXPECT_THROW(RenderSyntheticView(camera, {}, {}), std::invalid_argument);
  SyntheticViewOptions options;
  options.supersampling = 0;
  EXPECT_FALSE(options.Check());
  EXPECT_THROW(RenderSyntheticView(SyntheticCamera640(), {}, options), std::invalid_argument);
}

}  // namespace
}  // namespace arucoslam
