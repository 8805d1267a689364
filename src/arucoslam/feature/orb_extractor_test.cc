#include "arucoslam/feature/orb_extractor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "arucoslam/feature/orb_matcher.h"

namespace arucoslam {
namespace {

const std::string kEurocImages =
    std::string(ARUCOSLAM_TEST_DATA_DIR) + "/euroc_v101_micro/mav0/cam0/data";

cv::Mat LoadEurocFrame(int index) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(kEurocImages)) {
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return cv::imread(files.at(index).string(), cv::IMREAD_GRAYSCALE);
}

#define SKIP_WITHOUT_EUROC()                                                        \
  if (!std::filesystem::is_directory(kEurocImages)) {                               \
    GTEST_SKIP() << "test data missing: " << kEurocImages << " (euroc_v101_micro)"; \
  }

// Fraction of the cells of a cols x rows grid over the image holding at least one keypoint.
double OccupiedFraction(const OrbFeatures& features, int cols, int rows) {
  std::vector<int> counts(cols * rows, 0);
  for (const cv::KeyPoint& kp : features.keypoints) {
    const int cx = std::min(cols - 1, static_cast<int>(kp.pt.x * cols / features.image_width));
    const int cy = std::min(rows - 1, static_cast<int>(kp.pt.y * rows / features.image_height));
    ++counts[cy * cols + cx];
  }
  return static_cast<double>(
             std::count_if(counts.begin(), counts.end(), [](int c) { return c > 0; })) /
         counts.size();
}

TEST(OrbExtractorOptions, CheckRejectsBadValues) {
  OrbExtractorOptions options;
  EXPECT_TRUE(options.Check());
  options.scale_factor = 1.0;
  EXPECT_FALSE(options.Check());
  options = {};
  options.min_fast_threshold = 30;  // above the initial threshold
  EXPECT_FALSE(options.Check());
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "min_fast_threshold must be <= initial_fast_threshold (20), is 30");
  options = {};
  options.edge_margin_px = 10;  // smaller than the orientation patch
  EXPECT_FALSE(options.Check());
  options = {};
  options.num_threads = 0;
  EXPECT_FALSE(options.Check());
  options = {};
  options.num_features = 0;
  EXPECT_FALSE(options.Check());
  EXPECT_THROW(OrbExtractor{options}, std::invalid_argument);
}

TEST(OrbExtractor, FeaturesPerLevelFollowLevelArea) {
  const OrbExtractor extractor;
  const std::vector<int>& counts = extractor.features_per_level();
  ASSERT_EQ(counts.size(), 8u);
  EXPECT_EQ(std::accumulate(counts.begin(), counts.end(), 0), 1000);
  for (int level = 1; level + 1 < 8; ++level) {
    // Area ratio of consecutive levels is 1.2^2 = 1.44; rounding moves counts by <= 1.
    EXPECT_NEAR(counts[level - 1] / 1.44, counts[level], 1.0) << "level " << level;
  }
}

TEST(OrbExtractor, RejectsColourAndEmptyImages) {
  const OrbExtractor extractor;
  EXPECT_THROW(extractor.Extract(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(extractor.Extract(cv::Mat(100, 100, CV_8UC3, cv::Scalar::all(0))),
               std::invalid_argument);
}

TEST(OrbExtractor, FlatImageHasNoFeatures) {
  const OrbFeatures features = OrbExtractor().Extract(cv::Mat(480, 640, CV_8U, cv::Scalar(128)));
  EXPECT_TRUE(features.empty());
  EXPECT_EQ(features.descriptors.rows, 0);
  EXPECT_EQ(features.descriptors.cols, kOrbDescriptorBytes);
}

TEST(OrbExtractor, OrientationPointsToTheBrightSide) {
  // A blurred bright square on a dark background: at its top-left corner the intensity
  // centroid lies towards the square, i.e. at 45 degrees (x right, y down).
  cv::Mat image(200, 200, CV_8U, cv::Scalar(40));
  cv::rectangle(image, cv::Rect(90, 90, 20, 20), cv::Scalar(200), cv::FILLED);
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.0);
  OrbExtractorOptions options;
  options.num_levels = 1;
  const OrbFeatures features = OrbExtractor(options).Extract(image);
  ASSERT_FALSE(features.empty());
  const auto top_left = std::min_element(features.keypoints.begin(), features.keypoints.end(),
                                         [](const cv::KeyPoint& a, const cv::KeyPoint& b) {
                                           return a.pt.x + a.pt.y < b.pt.x + b.pt.y;
                                         });
  EXPECT_NEAR(top_left->pt.x, 90.0, 2.0);
  EXPECT_NEAR(top_left->pt.y, 90.0, 2.0);
  EXPECT_NEAR(top_left->angle, 45.0, 5.0);
}

TEST(OrbExtractor, OrientationTurnsWithTheImage) {
  // Turning the image by exactly 90 degrees (a pixel permutation) must move every level-0
  // keypoint to the turned position and add 90 degrees to its angle.
  cv::Mat image(240, 320, CV_8U);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(image, image, cv::Size(9, 9), 2.5);
  cv::normalize(image, image, 0, 255, cv::NORM_MINMAX);
  OrbExtractorOptions options;
  options.num_levels = 1;
  options.num_features = 100000;  // keep every corner: no selection that depends on layout
  options.min_fast_threshold = options.initial_fast_threshold;
  const OrbExtractor extractor(options);
  const OrbFeatures original = extractor.Extract(image);
  cv::Mat turned;
  cv::rotate(image, turned, cv::ROTATE_90_CLOCKWISE);
  const OrbFeatures rotated = extractor.Extract(turned);
  ASSERT_GT(original.size(), 100u);
  int compared = 0;
  for (const cv::KeyPoint& kp : original.keypoints) {
    const cv::Point2f expected(image.rows - 1 - kp.pt.y, kp.pt.x);
    const auto it =
        std::find_if(rotated.keypoints.begin(), rotated.keypoints.end(),
                     [&](const cv::KeyPoint& k) { return cv::norm(k.pt - expected) < 0.01; });
    ASSERT_TRUE(it != rotated.keypoints.end()) << "keypoint " << kp.pt << " lost";
    double difference = std::fmod(it->angle - kp.angle - 90.0 + 720.0, 360.0);
    difference = std::min(difference, 360.0 - difference);
    EXPECT_LT(difference, 0.5) << kp.pt;
    ++compared;
  }
  EXPECT_EQ(compared, static_cast<int>(original.size()));
  EXPECT_EQ(rotated.size(), original.size());
}

TEST(OrbExtractor, EurocFrameCountSpreadAndDeterminism) {
  SKIP_WITHOUT_EUROC();
  const cv::Mat image = LoadEurocFrame(0);
  ASSERT_EQ(image.cols, 752);
  const OrbExtractor extractor;
  const OrbFeatures features = extractor.Extract(image);
  EXPECT_GE(features.size(), 900u);
  EXPECT_LE(features.size(), 1000u);
  EXPECT_EQ(features.descriptors.rows, static_cast<int>(features.size()));
  EXPECT_EQ(features.descriptors.type(), CV_8U);
  std::vector<int> per_level(8, 0);
  for (const cv::KeyPoint& kp : features.keypoints) {
    ASSERT_GE(kp.octave, 0);
    ASSERT_LT(kp.octave, 8);
    ++per_level[kp.octave];
    // Inside the image minus the (scaled) edge margin.
    const double margin = 16.0 * features.pyramid.scales[kp.octave] - 1.0;
    EXPECT_GE(kp.pt.x, margin);
    EXPECT_LE(kp.pt.x, image.cols - 1 - margin);
    EXPECT_GE(kp.angle, 0.0f);
    EXPECT_LT(kp.angle, 360.0f);
  }
  for (int level = 0; level < 8; ++level) EXPECT_GT(per_level[level], 0) << "level " << level;
  const double occupied = OccupiedFraction(features, 8, 6);
  RecordProperty("occupied_8x6", std::to_string(occupied));
  EXPECT_GE(occupied, 0.95);
  const OrbFeatures again = extractor.Extract(image);
  ASSERT_EQ(again.size(), features.size());
  EXPECT_EQ(cv::norm(again.descriptors, features.descriptors, cv::NORM_L1), 0.0);
}

// Keypoints (position, level, orientation, size, score) and descriptors are bit for bit equal.
void ExpectIdentical(const OrbFeatures& a, const OrbFeatures& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.descriptors.rows, b.descriptors.rows);
  ASSERT_EQ(a.descriptors.type(), b.descriptors.type());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const cv::KeyPoint &ka = a.keypoints[i], &kb = b.keypoints[i];
    ASSERT_EQ(ka.pt.x, kb.pt.x) << i;
    ASSERT_EQ(ka.pt.y, kb.pt.y) << i;
    ASSERT_EQ(ka.octave, kb.octave) << i;
    ASSERT_EQ(ka.angle, kb.angle) << i;
    ASSERT_EQ(ka.size, kb.size) << i;
    ASSERT_EQ(ka.response, kb.response) << i;
  }
  if (a.descriptors.rows > 0) {
    EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_HAMMING), 0.0);
  }
}

// The same image through extractors with 1, 2 and 3 threads.
void ExpectSameForAnyThreadCount(const cv::Mat& image, OrbExtractorOptions options = {}) {
  options.num_threads = 1;
  const OrbFeatures single = OrbExtractor(options).Extract(image);
  for (int threads : {2, 3}) {
    options.num_threads = threads;
    const OrbExtractor extractor(options);
    SCOPED_TRACE(testing::Message() << threads << " threads");
    ExpectIdentical(extractor.Extract(image), single);
    ExpectIdentical(extractor.Extract(image), single);  // the pool's second loop
  }
}

// Smoothed noise of the given size, fixed seed.
cv::Mat SyntheticImage(cv::Size size) {
  cv::Mat noise(size, CV_8U);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat image;
  cv::GaussianBlur(noise, image, cv::Size(5, 5), 1.5);
  return image;
}

TEST(OrbExtractor, ThreadCountDoesNotChangeTheOutputOnSyntheticImages) {
  ExpectSameForAnyThreadCount(SyntheticImage(cv::Size(640, 480)));
  // Small: the last levels are too small for keypoints or vanish.
  ExpectSameForAnyThreadCount(SyntheticImage(cv::Size(90, 70)));
  OrbExtractorOptions options;
  options.num_features = 2500;
  options.num_levels = 12;
  ExpectSameForAnyThreadCount(SyntheticImage(cv::Size(1226, 370)), options);
}

TEST(OrbExtractor, ThreadCountDoesNotChangeTheOutputOnRealImages) {
  SKIP_WITHOUT_EUROC();
  const cv::Mat euroc = LoadEurocFrame(10);
  ExpectSameForAnyThreadCount(euroc(cv::Rect((euroc.cols - 640) / 2, 0, 640, 480)).clone());
  const std::string kitti =
      std::string(ARUCOSLAM_TEST_DATA_DIR) + "/kitti07_first160/original/image_0/000000.png";
  if (!std::filesystem::exists(kitti)) GTEST_SKIP() << "test data missing: " << kitti;
  ExpectSameForAnyThreadCount(cv::imread(kitti, cv::IMREAD_GRAYSCALE));
}

// Warps the image with a similarity about its centre and checks that keypoints come back at
// the mapped positions and that their descriptors still match the right partner.
struct Repeatability {
  double repeated = 0.0;         // fraction of visible keypoints re-detected within 2 px * scale
  double correct_matches = 0.0;  // fraction of brute-force matches that land within that radius
  double angle_error_deg = 0.0;  // median |(angle2 - angle1) - rotation|
  int num_matches = 0;
};

// cv::ORB (1000 features, 8 levels, 1.2) in the same containers, as the reference.
struct OpenCvOrb {
  OrbFeatures operator()(const cv::Mat& image) const {
    OrbFeatures features;
    cv::ORB::create(1000, 1.2f, 8)
        ->detectAndCompute(image, cv::noArray(), features.keypoints, features.descriptors);
    features.pyramid = ScalePyramid::Make(8, 1.2);
    features.image_width = image.cols;
    features.image_height = image.rows;
    return features;
  }
};

struct OwnOrb {
  OrbFeatures operator()(const cv::Mat& image) const { return OrbExtractor().Extract(image); }
};

template <typename Extract>
Repeatability MeasureUnderSimilarity(const cv::Mat& image, double angle_deg, double scale,
                                     const Extract& extract) {
  const cv::Point2f centre(image.cols / 2.0f, image.rows / 2.0f);
  const cv::Mat warp = cv::getRotationMatrix2D(centre, angle_deg, scale);  // CCW on screen
  cv::Mat warped;
  cv::warpAffine(image, warped, warp, image.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  const OrbFeatures original = extract(image);
  const OrbFeatures moved = extract(warped);
  auto map_point = [&](const cv::Point2f& p) {
    return cv::Point2f(
        warp.at<double>(0, 0) * p.x + warp.at<double>(0, 1) * p.y + warp.at<double>(0, 2),
        warp.at<double>(1, 0) * p.x + warp.at<double>(1, 1) * p.y + warp.at<double>(1, 2));
  };
  auto inside = [&](const cv::Point2f& q) {
    return q.x >= 40 && q.y >= 40 && q.x <= image.cols - 40 && q.y <= image.rows - 40;
  };
  Repeatability result;
  int visible = 0, repeated = 0;
  for (const cv::KeyPoint& kp : original.keypoints) {
    if (!inside(map_point(kp.pt))) continue;
    const cv::Point2f q = map_point(kp.pt);
    ++visible;
    const double radius = 2.0 * original.pyramid.scales[kp.octave];
    for (const cv::KeyPoint& other : moved.keypoints) {
      if (cv::norm(other.pt - q) <= radius) {
        ++repeated;
        break;
      }
    }
  }
  result.repeated = static_cast<double>(repeated) / std::max(1, visible);
  BruteForceMatchOptions match_options;
  match_options.check_rotation = false;
  const std::vector<FeatureMatch> matches = MatchBruteForce(original, moved, match_options);
  int correct = 0;
  std::vector<double> angle_errors;
  int considered = 0;
  for (const FeatureMatch& m : matches) {
    const cv::KeyPoint& a = original.keypoints[m.index1];
    const cv::KeyPoint& b = moved.keypoints[m.index2];
    // Only features that are visible in both images can have a correct partner.
    if (!inside(map_point(a.pt))) continue;
    ++considered;
    if (cv::norm(b.pt - map_point(a.pt)) > 3.0 * original.pyramid.scales[a.octave]) continue;
    ++correct;
    // Image y points down, so a counter-clockwise turn on screen lowers the angle.
    double error = std::fmod(b.angle - a.angle + angle_deg + 720.0, 360.0);
    angle_errors.push_back(std::min(error, 360.0 - error));
  }
  result.num_matches = considered;
  result.correct_matches = static_cast<double>(correct) / std::max(1, considered);
  if (!angle_errors.empty()) {
    std::nth_element(angle_errors.begin(), angle_errors.begin() + angle_errors.size() / 2,
                     angle_errors.end());
    result.angle_error_deg = angle_errors[angle_errors.size() / 2];
  }
  return result;
}

// Our matches under a known warp must be right at least 85% of the time (brute force, ratio
// 0.8, cross-check) and not less often than cv::ORB's minus 3 points.
void ExpectRepeatable(double angle_deg, double scale, double min_repeated) {
  const cv::Mat image = LoadEurocFrame(10);
  const Repeatability own = MeasureUnderSimilarity(image, angle_deg, scale, OwnOrb());
  const Repeatability reference = MeasureUnderSimilarity(image, angle_deg, scale, OpenCvOrb());
  ::testing::Test::RecordProperty("repeated", std::to_string(own.repeated));
  ::testing::Test::RecordProperty("correct_matches", std::to_string(own.correct_matches));
  ::testing::Test::RecordProperty("opencv_correct_matches",
                                  std::to_string(reference.correct_matches));
  EXPECT_GE(own.repeated, min_repeated);
  EXPECT_GE(own.num_matches, 150);
  EXPECT_GE(own.correct_matches, 0.85);
  EXPECT_GE(own.correct_matches, reference.correct_matches - 0.03);
  EXPECT_LE(own.angle_error_deg, 5.0);
}

TEST(OrbExtractor, RepeatableUnderKnownRotation) {
  SKIP_WITHOUT_EUROC();
  ExpectRepeatable(30.0, 1.0, 0.5);
}

TEST(OrbExtractor, RepeatableUnderKnownScaling) {
  SKIP_WITHOUT_EUROC();
  ExpectRepeatable(0.0, 0.8, 0.4);
}

}  // namespace
}  // namespace arucoslam
