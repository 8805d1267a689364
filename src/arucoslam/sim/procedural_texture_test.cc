#include "arucoslam/sim/procedural_texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace arucoslam {
namespace {

bool SamePixels(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// Standard deviation of the grey-level Laplacian: how much fine detail there is.
double DetailEnergy(const cv::Mat& bgr) {
  cv::Mat grey, laplacian;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::Laplacian(grey, laplacian, CV_32F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(laplacian, mean, stddev);
  return stddev[0];
}

TEST(SeededRandomTest, RangesAndMoments) {
  SeededRandom random(42);
  double sum = 0.0, sum_sq = 0.0;
  int low_hits = 0, high_hits = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const double u = random.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    const int k = random.Int(3, 7);
    ASSERT_GE(k, 3);
    ASSERT_LE(k, 7);
    low_hits += k == 3;
    high_hits += k == 7;
    const double g = random.Gaussian();
    sum += g;
    sum_sq += g * g;
  }
  EXPECT_NEAR(low_hits / static_cast<double>(n), 0.2, 0.01);
  EXPECT_NEAR(high_hits / static_cast<double>(n), 0.2, 0.01);
  EXPECT_NEAR(sum / n, 0.0, 0.02);
  EXPECT_NEAR(std::sqrt(sum_sq / n), 1.0, 0.02);
  SeededRandom a(7), b(7), c(8);
  EXPECT_EQ(a.Next(), b.Next());
  EXPECT_NE(a.Next(), c.Next());
}

TEST(ProceduralTextureTest, NoiseIsSmoothAndInRange) {
  const cv::Mat noise = FractalNoise(256, 128, 64.0, 4, 3);
  ASSERT_EQ(noise.type(), CV_32FC1);
  double low, high;
  cv::minMaxLoc(noise, &low, &high);
  EXPECT_GE(low, 0.0);
  EXPECT_LE(high, 1.0);
  EXPECT_GT(high - low, 0.3);
  // Neighbouring pixels differ far less than the overall spread.
  cv::Mat dx = cv::abs(noise.colRange(1, 256) - noise.colRange(0, 255));
  EXPECT_LT(cv::mean(dx)[0], 0.05 * (high - low));
}

TEST(ProceduralTextureTest, SameSeedSamePixelsOtherSeedOthers) {
  EXPECT_TRUE(SamePixels(ConcreteFloorTexture(256, 1.0, 9), ConcreteFloorTexture(256, 1.0, 9)));
  EXPECT_FALSE(SamePixels(ConcreteFloorTexture(256, 1.0, 9), ConcreteFloorTexture(256, 1.0, 10)));
  EXPECT_TRUE(SamePixels(PosterTexture(180, 256, 4), PosterTexture(180, 256, 4)));
  EXPECT_TRUE(SamePixels(CardboardTexture(128, 1.0, 4), CardboardTexture(128, 1.0, 4)));
  const cv::Mat machine = MachinePanelTexture(384, 256, cv::Scalar(90, 130, 60), 2);
  EXPECT_TRUE(SamePixels(machine, MachinePanelTexture(384, 256, cv::Scalar(90, 130, 60), 2)));
  EXPECT_EQ(machine.type(), CV_8UC3);
  EXPECT_EQ(machine.cols, 384);
  EXPECT_EQ(machine.rows, 256);
}

// Walls stay low-texture at every level, and the level scales their detail.
TEST(ProceduralTextureTest, TextureLevelScalesDetail) {
  const cv::Scalar paint(214, 220, 222), band(150, 160, 140);
  auto wall = [&](TextureLevel level) {
    return PaintedWallTexture(512, 768, paint, band, 0.2, TextureDetail(level), 11);
  };
  const double low = DetailEnergy(wall(TextureLevel::kLow));
  const double medium = DetailEnergy(wall(TextureLevel::kMedium));
  const double high = DetailEnergy(wall(TextureLevel::kHigh));
  EXPECT_LT(low, medium);
  EXPECT_LT(medium, high);
  // A painted wall has much less fine detail than a poster or a machine side.
  EXPECT_LT(high, 0.5 * DetailEnergy(PosterTexture(512, 768, 11)));
  EXPECT_LT(high, 0.5 * DetailEnergy(MachinePanelTexture(512, 768, cv::Scalar(90, 130, 60), 11)));
  // The floor is faint: its mean colour is concrete grey and its spread small.
  cv::Scalar mean, stddev;
  cv::meanStdDev(ConcreteFloorTexture(512, 1.0, 5), mean, stddev);
  EXPECT_NEAR(mean[1], 142.0, 15.0);
  EXPECT_LT(stddev[1], 20.0);
}

}  // namespace
}  // namespace arucoslam
