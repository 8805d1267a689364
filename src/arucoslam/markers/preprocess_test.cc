#include "arucoslam/markers/preprocess.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace arucoslam {
namespace {

cv::Mat NoisyFlat(double level, double sigma, const cv::Size& size = {200, 200}) {
  cv::Mat noise(size, CV_32F);
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::NORMAL, level, sigma);
  cv::Mat image;
  noise.convertTo(image, CV_8U);
  return image;
}

double StdDev(const cv::Mat& image) {
  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  return stddev[0];
}

TEST(PreprocessTest, ColourAndSixteenBitBecomeEightBitGrey) {
  cv::Mat bgr(4, 4, CV_8UC3, cv::Scalar(10, 100, 200));
  const cv::Mat grey = Preprocess(bgr);
  ASSERT_EQ(grey.type(), CV_8UC1);
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(grey, expected, cv::NORM_INF), 0.0);
  const cv::Mat wide(4, 4, CV_16UC1, cv::Scalar(257 * 77));
  const cv::Mat narrowed = Preprocess(wide);
  ASSERT_EQ(narrowed.type(), CV_8UC1);
  EXPECT_EQ(narrowed.at<uint8_t>(2, 2), 77);
  // The input is left unchanged.
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(10, 100, 200));
}

// A dim, low-contrast pattern (blocks of grey 30 or 40): CLAHE spreads it, more with a higher
// clip limit (the local mapping's slope is bounded by the clip limit).
TEST(PreprocessTest, ClaheRaisesLowContrast) {
  cv::Mat blocks(200, 200, CV_8U);
  cv::RNG rng(3);
  for (int r = 0; r < 200; r += 10) {
    for (int c = 0; c < 200; c += 10) {
      blocks(cv::Rect(c, r, 10, 10)).setTo(rng.uniform(0, 2) ? 40 : 30);
    }
  }
  PreprocessOptions options;
  options.clahe = true;
  options.clahe_clip_limit = 2.0;
  const double mild = StdDev(Preprocess(blocks, options));
  options.clahe_clip_limit = 40.0;
  const double strong = StdDev(Preprocess(blocks, options));
  std::printf("std: input %.2f, clip 2 %.2f, clip 40 %.2f\n", StdDev(blocks), mild, strong);
  EXPECT_GT(mild, 1.1 * StdDev(blocks));
  EXPECT_GT(strong, 2.0 * mild);
}

TEST(PreprocessTest, GaussianDenoiseReducesNoise) {
  const cv::Mat noisy = NoisyFlat(128, 10.0);
  PreprocessOptions options;
  options.denoise = DenoiseMethod::kGaussian;
  options.gaussian_sigma_px = 1.0;
  // White noise of sigma s blurred by a Gaussian of sigma g keeps s / (2 sqrt(pi) g).
  EXPECT_NEAR(StdDev(Preprocess(noisy, options)), 10.0 / (2.0 * std::sqrt(M_PI)), 0.6);
}

TEST(PreprocessTest, BilateralDenoiseKeepsEdges) {
  cv::Mat step = NoisyFlat(60, 4.0);
  step(cv::Rect(100, 0, 100, 200)) += cv::Scalar(120);
  PreprocessOptions options;
  options.denoise = DenoiseMethod::kBilateral;
  const cv::Mat filtered = Preprocess(step, options);
  EXPECT_LT(StdDev(filtered(cv::Rect(10, 10, 80, 180))),
            0.6 * StdDev(step(cv::Rect(10, 10, 80, 180))));
  // The step stays sharp: one pixel each side of the edge still differs by > 100 levels.
  EXPECT_GT(cv::mean(filtered(cv::Rect(100, 0, 1, 200)))[0] -
                cv::mean(filtered(cv::Rect(99, 0, 1, 200)))[0],
            100.0);
}

TEST(PreprocessTest, BadOptionsAndEmptyImageAreRejected) {
  PreprocessOptions options;
  EXPECT_TRUE(options.Check());
  options.clahe = true;
  options.clahe_clip_limit = 0.0;
  EXPECT_FALSE(options.Check());
  EXPECT_THROW(Preprocess(NoisyFlat(1, 1), options), std::invalid_argument);
  options = {};
  options.denoise = DenoiseMethod::kBilateral;
  options.bilateral_diameter_px = 1;
  EXPECT_FALSE(options.Check());
  EXPECT_THROW(Preprocess(cv::Mat()), std::invalid_argument);
}

}  // namespace
}  // namespace arucoslam
