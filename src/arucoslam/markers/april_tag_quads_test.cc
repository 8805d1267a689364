#include "arucoslam/markers/april_tag_quads.h"

#include <gtest/gtest.h>

#include "arucoslam/markers/dictionary.h"
#include "arucoslam/markers/synthetic_view.h"

namespace arucoslam {
namespace {

Quad Square(float x0, float y0, float side) {
  return {cv::Point2f(x0, y0), cv::Point2f(x0 + side, y0), cv::Point2f(x0 + side, y0 + side),
          cv::Point2f(x0, y0 + side)};
}

// A 100 px marker of 10 cells (10 px each): the quad one cell inside it, the quad one cell
// outside it (the quiet zone's edge) and the marker's own, moved by 3 px and rotated in
// order and winding.
TEST(AprilTagQuadsTest, SnapsToTheNearestQuadKeepingTheDetectionsOrder) {
  const Quad inner = Square(110, 110, 80), outer = Square(90, 90, 120);
  Quad own = Square(103, 97, 100);
  std::reverse(own.begin(), own.end());  // counter-clockwise, starting elsewhere
  std::array<Eigen::Vector2d, 4> corners = {Eigen::Vector2d(100, 100), Eigen::Vector2d(200, 100),
                                            Eigen::Vector2d(200, 200), Eigen::Vector2d(100, 200)};
  ASSERT_TRUE(SnapCornersToQuad({inner, outer, own}, 10, 1.0, corners));
  EXPECT_NEAR((corners[0] - Eigen::Vector2d(103, 97)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((corners[1] - Eigen::Vector2d(203, 97)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((corners[2] - Eigen::Vector2d(203, 197)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((corners[3] - Eigen::Vector2d(103, 197)).norm(), 0.0, 1e-9);
}

// Quads one cell inside and outside are 1.4 cells away at each corner: not taken at 1 cell.
TEST(AprilTagQuadsTest, KeepsCornersWhenNoQuadIsWithinTheTolerance) {
  const std::array<Eigen::Vector2d, 4> found = {
      Eigen::Vector2d(100, 100), Eigen::Vector2d(200, 100), Eigen::Vector2d(200, 200),
      Eigen::Vector2d(100, 200)};
  std::array<Eigen::Vector2d, 4> corners = found;
  EXPECT_FALSE(SnapCornersToQuad({Square(110, 110, 80), Square(90, 90, 120)}, 10, 1.0, corners));
  EXPECT_EQ(corners, found);
  EXPECT_FALSE(SnapCornersToQuad({}, 10, 1.0, corners));
  EXPECT_EQ(corners, found);
}

// On a rendered tag36h11 marker the AprilTag quad fit finds a quad within 0.3 px of the
// projected corners (OpenCV's pixel centres).
TEST(AprilTagQuadsTest, FindsTheQuadOfARenderedTag) {
  const CameraModel camera = SyntheticCamera640();
  SyntheticMarker marker;
  marker.dictionary = "DICT_APRILTAG_36h11";
  marker.id = 7;
  marker.cam_from_marker =
      Rigid3(Eigen::Matrix3d(Eigen::AngleAxisd(0.5, Eigen::Vector3d(0.6, 0.8, 0)) *
                             Eigen::Vector3d(1, -1, -1).asDiagonal()),
             Eigen::Vector3d(0.05, -0.03, 1.0));
  const cv::Mat image = RenderSyntheticView(camera, {marker}, {});
  const std::vector<Quad> quads = FindAprilTagQuads(image, DictionaryFromName(marker.dictionary),
                                                    *cv::aruco::DetectorParameters::create());
  ASSERT_FALSE(quads.empty());
  std::array<Eigen::Vector2d, 4> corners = ProjectMarkerCorners(camera, marker);
  const std::array<Eigen::Vector2d, 4> truth = corners;
  ASSERT_TRUE(SnapCornersToQuad(quads, 10, 1.0, corners));
  for (int k = 0; k < 4; ++k) {
    std::printf("corner %d: %.3f px from the truth\n", k, (corners[k] - truth[k]).norm());
    EXPECT_LT((corners[k] - truth[k]).norm(), 0.3);
  }
}

}  // namespace
}  // namespace arucoslam
