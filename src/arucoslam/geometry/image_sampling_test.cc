// BilinearGrey against values worked out by hand on a 3 x 3 image.
#include "arucoslam/geometry/image_sampling.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

// 0 10 20 / 30 40 50 / 60 70 80.
cv::Mat Ramp() { return (cv::Mat_<uchar>(3, 3) << 0, 10, 20, 30, 40, 50, 60, 70, 80); }

TEST(BilinearGreyTest, PixelCentresReadTheirOwnValue) {
  const cv::Mat gray = Ramp();
  EXPECT_DOUBLE_EQ(BilinearGrey(gray, 0.0, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(BilinearGrey(gray, 1.0, 0.0), 10.0);
  EXPECT_DOUBLE_EQ(BilinearGrey(gray, 1.0, 1.0), 40.0);
  EXPECT_DOUBLE_EQ(BilinearGrey(gray, 0.0, 1.0), 30.0);
}

TEST(BilinearGreyTest, InterpolatesBetweenTheFourNeighbours) {
  const cv::Mat gray = Ramp();
  // Midway between 0, 10, 30, 40.
  EXPECT_NEAR(BilinearGrey(gray, 0.5, 0.5), 20.0, 1e-12);
  // Rows 0 and 1 at x = 1.25: 12.5 and 42.5, half of each.
  EXPECT_NEAR(BilinearGrey(gray, 1.25, 0.5), 27.5, 1e-12);
  // Rows 1 and 2 at x = 0.3: 33 and 63, weighted 0.4 and 0.6.
  EXPECT_NEAR(BilinearGrey(gray, 0.3, 1.6), 51.0, 1e-12);
}

TEST(BilinearGreyTest, ClampsPointsOffTheImageOntoIt) {
  const cv::Mat gray = Ramp();
  // (-5, 10) -> (0, 1.999): 0.001 * 30 + 0.999 * 60.
  EXPECT_NEAR(BilinearGrey(gray, -5.0, 10.0), 59.97, 1e-9);
  // The last pixel (2, 2) is read at (1.999, 1.999): 0.001 * 49.99 + 0.999 * 79.99.
  EXPECT_NEAR(BilinearGrey(gray, 2.0, 2.0), 79.96, 1e-9);
}

TEST(BilinearGreyTest, FollowsTheRowStrideOfAView) {
  cv::Mat wide(4, 6, CV_8UC1, cv::Scalar(255));
  Ramp().copyTo(wide(cv::Rect(2, 1, 3, 3)));
  const cv::Mat view = wide(cv::Rect(2, 1, 3, 3));
  EXPECT_NEAR(BilinearGrey(view, 0.3, 1.6), 51.0, 1e-12);
}

}  // namespace
}  // namespace arucoslam
