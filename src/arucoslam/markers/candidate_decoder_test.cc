#include "arucoslam/markers/candidate_decoder.h"

#include <gtest/gtest.h>

#include <random>

#include "arucoslam/markers/dictionary.h"
#include "arucoslam/markers/synthetic_view.h"

namespace arucoslam {
namespace {

// Given its true corners, perturbed by up to 1 px and starting at any of the four corners in
// either winding, a rendered marker decodes to its id with the corners back in OpenCV order.
TEST(CandidateDecoderTest, DecodesRenderedMarkerFromAnyCornerOrder) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary = DictionaryFromName("DICT_4X4_50");
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> jitter(-0.7f, 0.7f);
  int decoded_count = 0;
  double worst = 0.0;
  for (int i = 0; i < 12; ++i) {
    SyntheticMarker marker;
    marker.id = 3 * i + 1;
    marker.cam_from_marker =
        Rigid3(Eigen::Matrix3d(Eigen::AngleAxisd(0.5, Eigen::Vector3d(0.6, 0.8, 0)) *
                               Eigen::Vector3d(1, -1, -1).asDiagonal() *
                               Eigen::AngleAxisd(0.5 * i, Eigen::Vector3d::UnitZ())),
               Eigen::Vector3d(0.02 * i - 0.1, 0.05, 1.0 + 0.2 * i));
    SyntheticViewOptions view;
    view.seed = 20 + i;
    const cv::Mat image = RenderSyntheticView(SyntheticCamera640(), {marker}, view);
    const auto truth = ProjectMarkerCorners(SyntheticCamera640(), marker);
    std::array<cv::Point2f, 4> corners;
    const int start = i % 4;
    const bool reversed = i % 2 == 1;
    for (int k = 0; k < 4; ++k) {
      const int index = reversed ? (start + 4 - k) % 4 : (start + k) % 4;
      corners[k] = cv::Point2f(static_cast<float>(truth[index].x()) + jitter(rng),
                               static_cast<float>(truth[index].y()) + jitter(rng));
    }
    const std::optional<DecodedCandidate> decoded =
        DecodeCandidate(image, corners, *dictionary, CandidateDecoderOptions{});
    ASSERT_TRUE(decoded.has_value()) << "marker " << marker.id;
    EXPECT_EQ(decoded->id, marker.id);
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d corner(decoded->corners[k].x, decoded->corners[k].y);
      worst = std::max(worst, (corner - truth[k]).norm());
    }
    ++decoded_count;
  }
  std::printf("worst corner after refinement: %.3f px\n", worst);
  EXPECT_EQ(decoded_count, 12);
  EXPECT_LT(worst, 0.6);  // refined back from up to 1 px off
}

// Random quadrilaterals over texture and plain grey decode to nothing.
TEST(CandidateDecoderTest, RandomQuadrilateralsAreNotMarkers) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary = DictionaryFromName("DICT_4X4_50");
  SyntheticViewOptions view;
  view.texture_contrast = 60.0;
  const cv::Mat textured = RenderSyntheticView(SyntheticCamera640(), {}, view);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> centre_x(60, 580), centre_y(60, 420), size(12, 50),
      wobble(-0.2f, 0.2f);
  int false_decodes = 0;
  for (int i = 0; i < 2000; ++i) {
    const float cx = centre_x(rng), cy = centre_y(rng), half = 0.5f * size(rng);
    std::array<cv::Point2f, 4> corners;
    const float signs[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int k = 0; k < 4; ++k) {
      corners[k] = {cx + half * (signs[k][0] + wobble(rng)),
                    cy + half * (signs[k][1] + wobble(rng))};
    }
    false_decodes +=
        DecodeCandidate(textured, corners, *dictionary, CandidateDecoderOptions{}).has_value();
  }
  std::printf("false decodes: %d of 2000 random quadrilaterals\n", false_decodes);
  EXPECT_EQ(false_decodes, 0);
  const cv::Mat plain(480, 640, CV_8UC1, cv::Scalar(128));
  EXPECT_FALSE(DecodeCandidate(plain, {{{100, 100}, {140, 100}, {140, 140}, {100, 140}}},
                               *dictionary, CandidateDecoderOptions{})
                   .has_value());
}

TEST(CandidateDecoderTest, OptionsAreChecked) {
  CandidateDecoderOptions options;
  EXPECT_TRUE(options.Check());
  options.ignored_margin_per_cell = 0.5;
  EXPECT_FALSE(options.Check());
  options = {};
  options.samples_per_cell = 0;
  EXPECT_FALSE(options.Check());
  options = {};
  options.error_correction_rate = 1.5;
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace arucoslam
