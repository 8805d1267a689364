#include "arucoslam/markers/threshold_line_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "arucoslam/markers/edge_refiner.h"
#include "arucoslam/markers/synthetic_view.h"

namespace arucoslam {
namespace {

std::array<cv::Point2f, 4> ToPoints(const std::array<Eigen::Vector2d, 4>& corners) {
  std::array<cv::Point2f, 4> points;
  for (int k = 0; k < 4; ++k) {
    points[k] = cv::Point2f(static_cast<float>(corners[k].x()), static_cast<float>(corners[k].y()));
  }
  return points;
}

double Distance(cv::Point2f a, const Eigen::Vector2d& b) {
  return std::hypot(a.x - b.x(), a.y - b.y());
}

// Small tilted AprilTags (sides of 11-40 px, 1.4-5 px per cell; blurred, noisy, JPEG):
// corners displaced by up to 0.6 px each way come back to the rendered truth, closer than
// the edge refiner of the rescue decoder brings them (measured: mean 0.11 against 0.19 px).
TEST(ThresholdLineFitTest, SmallTiltedTagsFromDisplacedQuads) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<float> jitter(-0.6f, 0.6f);
  double sum = 0.0, worst = 0.0, sum_edges = 0.0;
  int fitted = 0, tried = 0, edges_fitted = 0;
  for (int image_index = 0; image_index < 4; ++image_index) {
    std::vector<SyntheticMarker> markers;
    for (int i = 0; i < 6; ++i) {
      SyntheticMarker marker;
      marker.dictionary = "DICT_APRILTAG_36h11";
      marker.id = 6 * image_index + i;
      marker.size = 0.1;
      marker.quiet_zone_cells = 1.0 + unit(rng);
      const Eigen::Vector3d axis(std::cos(6.0 * unit(rng)), std::sin(6.0 * unit(rng)), 0.0);
      const double depth = 1.2 + 1.8 * unit(rng);
      marker.cam_from_marker =
          Rigid3(Eigen::Matrix3d(Eigen::AngleAxisd(0.2 + 0.9 * unit(rng), axis.normalized()) *
                                 Eigen::AngleAxisd(6.28 * unit(rng), Eigen::Vector3d::UnitZ()) *
                                 Eigen::Vector3d(1, -1, -1).asDiagonal()),
                 Eigen::Vector3d((i % 3 - 1) * 0.25 * depth, (i / 3 - 0.5) * 0.35 * depth, depth));
      markers.push_back(marker);
    }
    SyntheticViewOptions view;
    view.seed = 40 + image_index;
    view.blur_sigma_px = 0.6 + 0.15 * image_index;
    const cv::Mat image = ThroughJpeg(RenderSyntheticView(SyntheticCamera640(), markers, view), 85);
    for (const SyntheticMarker& marker : markers) {
      const std::array<Eigen::Vector2d, 4> truth = ProjectMarkerCorners(SyntheticCamera640(), marker);
      std::array<cv::Point2f, 4> start = ToPoints(truth);
      for (cv::Point2f& corner : start) corner += cv::Point2f(jitter(rng), jitter(rng));
      ++tried;
      std::array<cv::Point2f, 4> corners = start;
      const bool ok = FitQuadToThreshold(image, 8, ThresholdLineFitOptions{}, corners);
      if (ok) {
        ++fitted;
        for (int k = 0; k < 4; ++k) {
          sum += Distance(corners[k], truth[k]);
          worst = std::max(worst, Distance(corners[k], truth[k]));
        }
      }
      std::array<cv::Point2f, 4> edges = start;
      if (RefineQuadEdges(image, 8, EdgeRefineOptions{}, edges)) {
        ++edges_fitted;
        for (int k = 0; k < 4; ++k) sum_edges += Distance(edges[k], truth[k]);
      }
    }
  }
  std::printf(
      "threshold fit: %d of %d, corner error mean %.3f max %.3f px; "
      "edge refiner: %d, mean %.3f px\n",
      fitted, tried, sum / (4 * std::max(fitted, 1)), worst, edges_fitted,
      sum_edges / (4 * std::max(edges_fitted, 1)));
  EXPECT_EQ(fitted, tried);
  EXPECT_LT(sum / (4 * fitted), 0.15);
  EXPECT_LT(worst, 0.8);
  EXPECT_LT(sum / (4 * fitted), sum_edges / (4 * std::max(edges_fitted, 1)));
}

// Tags seen nearly edge-on (tilted 60-70 degrees about an axis near a diagonal: thin
// diamonds with acute corners of 31-57 degrees, 1.5-2.5 px per cell across): the acute
// corners, where a small error across a side moves the corner far along it, stay within
// 0.8 px of the truth. (At 75 degrees, corners of 22 degrees, errors reach 1 px.)
TEST(ThresholdLineFitTest, AcuteCornersOfTagsSeenEdgeOn) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<float> jitter(-0.7f, 0.7f);
  double sum = 0.0, worst = 0.0, sharpest = 180.0, bluntest = 0.0;
  int acute = 0, fitted = 0, tried = 0;
  for (int i = 0; i < 12; ++i) {
    SyntheticMarker marker;
    marker.dictionary = "DICT_APRILTAG_36h11";
    marker.id = i;
    marker.size = 0.1;
    marker.quiet_zone_cells = 1.0;
    const double tilt = (60.0 + 5.0 * (i % 3)) * M_PI / 180.0;
    marker.cam_from_marker = Rigid3(
        Eigen::Matrix3d(
            Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()) *
            Eigen::AngleAxisd(0.785 + 0.3 * (unit(rng) - 0.5), Eigen::Vector3d::UnitZ()) *
            Eigen::Vector3d(1, -1, -1).asDiagonal()),
        Eigen::Vector3d(0.2 * (unit(rng) - 0.5), 0.2 * (unit(rng) - 0.5), 1.2 + 0.6 * unit(rng)));
    SyntheticViewOptions view;
    view.seed = 300 + i;
    view.background = SyntheticBackground::kUniform;
    view.background_mean = 200.0;
    view.blur_sigma_px = 0.7 + 0.4 * unit(rng);
    const cv::Mat image = ThroughJpeg(RenderSyntheticView(SyntheticCamera640(), {marker}, view), 85);
    const std::array<Eigen::Vector2d, 4> truth = ProjectMarkerCorners(SyntheticCamera640(), marker);
    std::array<cv::Point2f, 4> corners = ToPoints(truth);
    for (cv::Point2f& corner : corners) corner += cv::Point2f(jitter(rng), jitter(rng));
    ++tried;
    if (!FitQuadToThreshold(image, 8, ThresholdLineFitOptions{}, corners)) continue;
    ++fitted;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d in = truth[(k + 3) % 4] - truth[k], out = truth[(k + 1) % 4] - truth[k];
      const double angle = std::acos(in.normalized().dot(out.normalized())) * 180.0 / M_PI;
      if (angle > 70.0) continue;
      ++acute;
      sharpest = std::min(sharpest, angle);
      bluntest = std::max(bluntest, angle);
      sum += Distance(corners[k], truth[k]);
      worst = std::max(worst, Distance(corners[k], truth[k]));
    }
  }
  std::printf(
      "edge-on: %d of %d fitted, %d acute corners (%.0f-%.0f deg), error mean %.3f max %.3f px\n",
      fitted, tried, acute, sharpest, bluntest, sum / std::max(acute, 1), worst);
  EXPECT_EQ(fitted, tried);
  EXPECT_EQ(acute, 2 * tried);
  EXPECT_LT(sum / acute, 0.3);
  EXPECT_LT(worst, 0.8);
}

// No threshold crossings of the right kind, no fit: a plain image, a bright square on a
// darker ground (a marker's paper, not its black square) and a quad half outside the image
// leave the corners as they were.
TEST(ThresholdLineFitTest, RefusesQuadsWithoutDarkInsideEdges) {
  const std::array<cv::Point2f, 4> start = {
      {{100.f, 100.f}, {140.f, 100.f}, {140.f, 140.f}, {100.f, 140.f}}};
  std::array<cv::Point2f, 4> corners = start;
  const cv::Mat plain(240, 320, CV_8UC1, cv::Scalar(128));
  EXPECT_FALSE(FitQuadToThreshold(plain, 8, ThresholdLineFitOptions{}, corners));
  cv::Mat bright(240, 320, CV_8UC1, cv::Scalar(90));
  bright(cv::Rect(101, 101, 39, 39)).setTo(210);
  EXPECT_FALSE(FitQuadToThreshold(bright, 8, ThresholdLineFitOptions{}, corners));
  for (int k = 0; k < 4; ++k) EXPECT_EQ(corners[k], start[k]);
  // A dark square whose left half is cut off by the image border.
  cv::Mat cut(240, 320, CV_8UC1, cv::Scalar(220));
  cut(cv::Rect(0, 100, 20, 40)).setTo(30);
  std::array<cv::Point2f, 4> outside = {
      {{-20.f, 100.f}, {20.f, 100.f}, {20.f, 140.f}, {-20.f, 140.f}}};
  const std::array<cv::Point2f, 4> outside_start = outside;
  EXPECT_FALSE(FitQuadToThreshold(cut, 8, ThresholdLineFitOptions{}, outside));
  for (int k = 0; k < 4; ++k) EXPECT_EQ(outside[k], outside_start[k]);
}

// A sharp dark square: the threshold crossings lie on the pixel boundaries, the corners where
// the square's sides are, in either winding of the corners.
TEST(ThresholdLineFitTest, SharpSquareInBothWindings) {
  cv::Mat image(120, 160, CV_8UC1, cv::Scalar(230));
  image(cv::Rect(50, 40, 32, 32)).setTo(20);  // pixels 50..81: sides at 49.5 and 81.5
  const std::array<cv::Point2d, 4> truth = {
      {{49.5, 39.5}, {81.5, 39.5}, {81.5, 71.5}, {49.5, 71.5}}};
  for (const bool clockwise : {true, false}) {
    std::array<cv::Point2f, 4> corners = {
        {{50.3f, 39.0f}, {81.0f, 40.2f}, {82.1f, 71.0f}, {49.2f, 72.0f}}};
    if (!clockwise) std::swap(corners[1], corners[3]);
    ASSERT_TRUE(FitQuadToThreshold(image, 8, ThresholdLineFitOptions{}, corners));
    for (int k = 0; k < 4; ++k) {
      const cv::Point2d expected = truth[clockwise || k % 2 == 0 ? k : 4 - k];
      EXPECT_NEAR(corners[k].x, expected.x, 0.01) << k;
      EXPECT_NEAR(corners[k].y, expected.y, 0.01) << k;
    }
  }
}

}  // namespace
}  // namespace arucoslam
