#include "arucoslam/feature/orb_matcher.h"

#include <gtest/gtest.h>

#include <random>

#include "arucoslam/feature/feature_grid.h"

namespace arucoslam {
namespace {

// Features with random descriptors at given positions/levels/angles.
OrbFeatures RandomFeatures(int count, std::uint32_t seed, cv::Size size = {640, 480}) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> x(20.0f, size.width - 20.0f), y(20.0f, size.height - 20.0f);
  OrbFeatures features;
  features.pyramid = ScalePyramid::Make(8, 1.2);
  features.image_width = size.width;
  features.image_height = size.height;
  features.descriptors.create(count, kOrbDescriptorBytes, CV_8U);
  for (int i = 0; i < count; ++i) {
    features.keypoints.emplace_back(x(rng), y(rng), 31.0f, static_cast<float>(rng() % 360), 1.0f,
                                    static_cast<int>(rng() % 3));
    for (int b = 0; b < kOrbDescriptorBytes; ++b) {
      features.descriptors.at<std::uint8_t>(i, b) = static_cast<std::uint8_t>(rng());
    }
  }
  return features;
}

// Copy of `features` whose descriptors have `flips` random bits flipped, keypoints moved by
// `shift` pixels and turned by `turn_deg`.
OrbFeatures Perturbed(const OrbFeatures& features, int flips, cv::Point2f shift, float turn_deg,
                      std::uint32_t seed) {
  std::mt19937 rng(seed);
  OrbFeatures copy = features;
  copy.descriptors = features.descriptors.clone();
  for (int i = 0; i < copy.descriptors.rows; ++i) {
    for (int f = 0; f < flips; ++f) {
      const int bit = static_cast<int>(rng() % 256);
      copy.descriptors.at<std::uint8_t>(i, bit / 8) ^= static_cast<std::uint8_t>(1u << (bit % 8));
    }
  }
  for (cv::KeyPoint& kp : copy.keypoints) {
    kp.pt += shift;
    kp.angle = std::fmod(kp.angle + turn_deg + 360.0f, 360.0f);
  }
  return copy;
}

int CountCorrect(const std::vector<FeatureMatch>& matches) {
  return static_cast<int>(std::count_if(
      matches.begin(), matches.end(), [](const FeatureMatch& m) { return m.index1 == m.index2; }));
}

TEST(HammingDistance, CountsDifferingBits) {
  std::uint8_t a[32] = {}, b[32] = {};
  EXPECT_EQ(HammingDistance(a, b), 0);
  b[0] = 0xFF;
  b[31] = 0x01;
  b[17] = 0x81;
  EXPECT_EQ(HammingDistance(a, b), 8 + 1 + 2);
  std::fill(std::begin(b), std::end(b), 0xFF);
  EXPECT_EQ(HammingDistance(a, b), 256);
  // Against OpenCV's norm on random data.
  std::mt19937 rng(3);
  for (int trial = 0; trial < 100; ++trial) {
    cv::Mat x(1, 32, CV_8U), y(1, 32, CV_8U);
    for (int k = 0; k < 32; ++k) {
      x.at<std::uint8_t>(k) = static_cast<std::uint8_t>(rng());
      y.at<std::uint8_t>(k) = static_cast<std::uint8_t>(rng());
    }
    EXPECT_EQ(HammingDistance(x.ptr<std::uint8_t>(), y.ptr<std::uint8_t>()),
              static_cast<int>(cv::norm(x, y, cv::NORM_HAMMING)));
  }
}

TEST(MatchBruteForce, FindsPerturbedCopies) {
  const OrbFeatures original = RandomFeatures(500, 1);
  // 20 of 256 bits flipped: far closer than random descriptors (~128 bits apart).
  const OrbFeatures copy = Perturbed(original, 20, {0, 0}, 0.0f, 2);
  const std::vector<FeatureMatch> matches = MatchBruteForce(original, copy);
  EXPECT_GE(matches.size(), 495u);
  EXPECT_EQ(CountCorrect(matches), static_cast<int>(matches.size()));
  for (const FeatureMatch& m : matches) EXPECT_LE(m.distance, 20);
  // Unrelated descriptors: nothing passes the 64-bit threshold.
  EXPECT_TRUE(MatchBruteForce(original, RandomFeatures(500, 9)).empty());
}

TEST(MatchBruteForce, RatioTestDropsAmbiguousMatches) {
  OrbFeatures first = RandomFeatures(2, 4);
  OrbFeatures second = RandomFeatures(2, 5);
  // Both descriptors of `second` are 10 and 12 bits from first[0]: ambiguous at ratio 0.8.
  first.descriptors.row(0).copyTo(second.descriptors.row(0));
  first.descriptors.row(0).copyTo(second.descriptors.row(1));
  second.descriptors.at<std::uint8_t>(0, 0) ^= 0xFF;  // 8 bits
  second.descriptors.at<std::uint8_t>(0, 1) ^= 0x03;  // +2 = 10
  second.descriptors.at<std::uint8_t>(1, 2) ^= 0xFF;  // 8 bits
  second.descriptors.at<std::uint8_t>(1, 3) ^= 0x0F;  // +4 = 12
  BruteForceMatchOptions options;
  options.check_rotation = false;
  EXPECT_TRUE(MatchBruteForce(first, second, options).empty());
  options.ratio = 1.0;  // disabled
  const std::vector<FeatureMatch> matches = MatchBruteForce(first, second, options);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].index2, 0);
  EXPECT_EQ(matches[0].distance, 10);
}

TEST(FilterByRotationConsistency, KeepsTheDominantRotation) {
  // 90 matches turned by ~40 degrees, 10 turned randomly: the random ones are dropped unless
  // they fall in the dominant bins.
  std::mt19937 rng(6);
  std::vector<float> angles1, angles2;
  std::vector<FeatureMatch> matches;
  int random_kept_possible = 0;
  for (int i = 0; i < 100; ++i) {
    const float a = static_cast<float>(rng() % 360);
    const float turn =
        i < 90 ? 40.0f + static_cast<float>(rng() % 5) : static_cast<float>(rng() % 360);
    if (i >= 90 && std::abs(turn - 42.0f) < 24.0f) ++random_kept_possible;
    angles1.push_back(a);
    angles2.push_back(std::fmod(a + turn, 360.0f));
    matches.push_back({i, i, 0});
  }
  const std::vector<FeatureMatch> kept = FilterByRotationConsistency(matches, angles1, angles2);
  int consistent = 0, random = 0;
  for (const FeatureMatch& m : kept) (m.index1 < 90 ? consistent : random)++;
  EXPECT_EQ(consistent, 90);
  EXPECT_LE(random, random_kept_possible);
  // Wrap-around: a turn of 359 degrees and one of 1 degree are 2 degrees apart.
  const std::vector<FeatureMatch> two = {{0, 0, 0}, {1, 1, 0}};
  EXPECT_EQ(FilterByRotationConsistency(two, {10.0f, 10.0f}, {9.0f, 11.0f}).size(), 2u);
}

TEST(FeatureGrid, FindsExactlyThePointsInTheCircle) {
  const OrbFeatures features = RandomFeatures(2000, 7);
  const FeatureGrid grid(features, 16.0);
  std::mt19937 rng(8);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector2d centre(rng() % 640, rng() % 480);
    const double radius = 5.0 + rng() % 60;
    std::vector<int> expected;
    for (int i = 0; i < static_cast<int>(features.size()); ++i) {
      const cv::KeyPoint& kp = features.keypoints[i];
      if (kp.octave < 1 || kp.octave > 2) continue;
      if (std::hypot(kp.pt.x - centre.x(), kp.pt.y - centre.y()) <= radius) expected.push_back(i);
    }
    std::vector<int> found = grid.FeaturesInRadius(centre, radius, 1, 2);
    std::sort(found.begin(), found.end());
    EXPECT_EQ(found, expected);
  }
}

TEST(MatchInWindow, MatchesShiftedFeaturesInsideTheWindowOnly) {
  const OrbFeatures first = RandomFeatures(400, 10);
  const OrbFeatures second = Perturbed(first, 15, {30.0f, -20.0f}, 25.0f, 11);
  const FeatureGrid grid(second);
  std::vector<Eigen::Vector2d> predicted;
  for (const cv::KeyPoint& kp : first.keypoints) predicted.emplace_back(kp.pt.x, kp.pt.y);
  WindowMatchOptions options;
  const std::vector<FeatureMatch> matches = MatchInWindow(first, second, grid, predicted, options);
  EXPECT_GE(matches.size(), 390u);
  EXPECT_EQ(CountCorrect(matches), static_cast<int>(matches.size()));
  // A window smaller than the 36 px shift finds nothing right.
  options.window_radius_px = 30.0;
  EXPECT_EQ(CountCorrect(MatchInWindow(first, second, grid, predicted, options)), 0);
  EXPECT_THROW(MatchInWindow(first, second, grid, {}, options), std::invalid_argument);
}

TEST(MatchByProjection, SearchRadiusGrowsWithTheLevel) {
  const OrbFeatures features = RandomFeatures(300, 12);
  const FeatureGrid grid(features);
  // Queries: the features' own descriptors, predicted 5 px to the right of the keypoint.
  std::vector<ProjectionQuery> queries;
  for (int i = 0; i < static_cast<int>(features.size()); ++i) {
    ProjectionQuery q;
    q.pixel = Eigen::Vector2d(features.keypoints[i].pt.x + 5.0, features.keypoints[i].pt.y);
    q.predicted_level = features.keypoints[i].octave;
    q.descriptor = features.Descriptor(i);
    queries.push_back(q);
  }
  ProjectionMatchOptions options;
  options.base_radius_px = 4.5;  // 4.5 * 1.2^level: < 5 at level 0, > 5 at levels 1 and 2
  const std::vector<FeatureMatch> matches = MatchByProjection(features, grid, queries, {}, options);
  int level0 = 0;
  for (const cv::KeyPoint& kp : features.keypoints) level0 += kp.octave == 0;
  EXPECT_EQ(static_cast<int>(matches.size()), static_cast<int>(features.size()) - level0);
  for (const FeatureMatch& m : matches) {
    EXPECT_EQ(m.index1, m.index2);
    EXPECT_EQ(m.distance, 0);
    EXPECT_GT(features.keypoints[m.index2].octave, 0);
  }
  // Features already taken are not offered again.
  std::vector<bool> taken(features.size(), true);
  EXPECT_TRUE(MatchByProjection(features, grid, queries, taken, options).empty());
}

TEST(MatchByProjection, EachFeatureGoesToTheClosestQuery) {
  const OrbFeatures features = RandomFeatures(1, 13);
  const FeatureGrid grid(features);
  cv::Mat near = features.descriptors.row(0).clone(), far = near.clone();
  near.at<std::uint8_t>(0) ^= 0x01;  // 1 bit
  far.at<std::uint8_t>(0) ^= 0x0F;   // 4 bits
  const Eigen::Vector2d at(features.keypoints[0].pt.x, features.keypoints[0].pt.y);
  const int level = features.keypoints[0].octave;
  const std::vector<ProjectionQuery> queries = {{at, level, far.ptr<std::uint8_t>()},
                                                {at, level, near.ptr<std::uint8_t>()}};
  const std::vector<FeatureMatch> matches = MatchByProjection(features, grid, queries, {});
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].index1, 1);
  EXPECT_EQ(matches[0].distance, 1);
}

}  // namespace
}  // namespace arucoslam
