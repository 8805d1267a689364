#include "arucoslam/markers/edge_refiner.h"

#include <gtest/gtest.h>

#include <random>

#include "arucoslam/markers/synthetic_view.h"

namespace arucoslam {
namespace {

// Small tilted markers (18-40 px, 3-7 px per cell, blurred and noisy): corners displaced by
// up to 1 px each way come back to the rendered truth.
TEST(EdgeRefinerTest, SmallMarkerCornersFromDisplacedQuads) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> jitter(-1.0f, 1.0f);
  double worst_before = 0.0, worst_after = 0.0, sum_after = 0.0;
  int refined = 0;
  for (int i = 0; i < 16; ++i) {
    SyntheticMarker marker;
    marker.id = i;
    marker.cam_from_marker =
        Rigid3(Eigen::Matrix3d(Eigen::AngleAxisd(0.6, Eigen::Vector3d(0.8, 0.6, 0)) *
                               Eigen::Vector3d(1, -1, -1).asDiagonal() *
                               Eigen::AngleAxisd(0.4 * i, Eigen::Vector3d::UnitZ())),
               Eigen::Vector3d(0.04 * i - 0.3, 0.1, 2.5 + 0.2 * i));
    SyntheticViewOptions view;
    view.seed = 70 + i;
    view.blur_sigma_px = 0.8;
    view.noise_sigma = 3.0;
    const cv::Mat image = RenderSyntheticView(SyntheticCamera640(), {marker}, view);
    const auto truth = ProjectMarkerCorners(SyntheticCamera640(), marker);
    std::array<cv::Point2f, 4> corners;
    for (int k = 0; k < 4; ++k) {
      // ProjectMarkerCorners runs clockwise on screen from the marker's top-left.
      corners[k] = cv::Point2f(static_cast<float>(truth[k].x()) + jitter(rng),
                               static_cast<float>(truth[k].y()) + jitter(rng));
      worst_before = std::max(worst_before, cv::norm(corners[k] - cv::Point2f(truth[k].x(),
                                                                               truth[k].y())));
    }
    if (!RefineQuadEdges(image, 6, EdgeRefineOptions{}, corners)) continue;
    ++refined;
    for (int k = 0; k < 4; ++k) {
      const double error = cv::norm(corners[k] - cv::Point2f(truth[k].x(), truth[k].y()));
      worst_after = std::max(worst_after, error);
      sum_after += error;
    }
  }
  std::printf("refined %d of 16; corner error before up to %.2f px, after mean %.3f max %.3f px\n",
              refined, worst_before, sum_after / (4 * std::max(refined, 1)), worst_after);
  EXPECT_EQ(refined, 16);
  EXPECT_LT(sum_after / (4 * refined), 0.25);
  EXPECT_LT(worst_after, 0.6);
}

// No edges, no refinement: a plain image and a bright square on a darker ground (the wrong
// polarity: a marker's paper, not its black square) leave the corners as they were.
TEST(EdgeRefinerTest, RefusesQuadsWithoutDarkInsideEdges) {
  const std::array<cv::Point2f, 4> start = {
      {{100.f, 100.f}, {140.f, 100.f}, {140.f, 140.f}, {100.f, 140.f}}};
  std::array<cv::Point2f, 4> corners = start;
  const cv::Mat plain(240, 320, CV_8UC1, cv::Scalar(128));
  EXPECT_FALSE(RefineQuadEdges(plain, 6, EdgeRefineOptions{}, corners));
  cv::Mat bright(240, 320, CV_8UC1, cv::Scalar(90));
  bright(cv::Rect(101, 101, 39, 39)).setTo(210);
  EXPECT_FALSE(RefineQuadEdges(bright, 6, EdgeRefineOptions{}, corners));
  for (int k = 0; k < 4; ++k) EXPECT_EQ(corners[k], start[k]);
}

}  // namespace
}  // namespace arucoslam
