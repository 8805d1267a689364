#include "arucoslam/io/lognav_import.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

void ExpectRejected(const std::string& text, const std::vector<std::string>& fragments,
                    const LognavImportOptions& options = {}) {
  try {
    ParseLognavMarkers(text, "list.json", options);
    ADD_FAILURE() << "accepted: " << text;
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "list.json");
    for (const std::string& fragment : fragments) {
      EXPECT_NE(error.message().find(fragment), std::string::npos)
          << "'" << fragment << "' not in: " << error.message();
    }
  }
}

// The box of their Gazebo model, posed `x y z 0 0 yaw`, printed on its +x face. By the
// box texture convention (docs/sdf_subset.md: on +x the image's right is +y, up is +z), the
// image's corners sit at box points (0, +-s/2, +-s/2); they must be the marker's corners.
TEST(LognavImportTest, CornersMatchTheTexturedFaceOfTheirBox) {
  for (const double yaw : {0.0, 1.58, -1.58, 3.0, -2.2}) {
    const Eigen::Vector3d position(-4.0, 0.6, 1.0);
    MarkerInfo marker;
    marker.size = 0.1;
    marker.world_from_marker = LognavWorldFromMarker(position.x(), position.y(), position.z(), yaw);
    const Eigen::Matrix3d world_from_box =
        Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const double h = 0.05;
    const Eigen::Vector3d image_corners_in_box[4] = {
        {0, -h, h}, {0, h, h}, {0, h, -h}, {0, -h, -h}};  // TL, TR, BR, BL of the image
    const auto corners = marker.CornersInWorld();
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d expected = world_from_box * image_corners_in_box[i] + position;
      EXPECT_LT((corners[i] - expected).norm(), 1e-12) << "yaw " << yaw << " corner " << i;
    }
    // The face normal is the box +x axis, horizontal.
    const Eigen::Vector3d normal = marker.world_from_marker.RotationMatrix().col(2);
    EXPECT_LT((normal - Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0)).norm(), 1e-12);
  }
}

// A camera in front of the marker, upright, looking at it: the marker's top-left corner
// must appear at the top left of the image (not mirrored, not upside down).
TEST(LognavImportTest, CameraInFrontSeesTheMarkerUpright) {
  const double yaw = -1.58;
  MarkerInfo marker;
  marker.size = 0.1;
  marker.world_from_marker = LognavWorldFromMarker(-4.0, 0.6, 1.0, yaw);
  const Eigen::Vector3d normal(std::cos(yaw), std::sin(yaw), 0.0);
  const Eigen::Vector3d camera = marker.world_from_marker.translation + 2.0 * normal;
  Eigen::Matrix3d world_from_cam;
  world_from_cam.col(2) = -normal;                    // forward, towards the marker
  world_from_cam.col(1) = -Eigen::Vector3d::UnitZ();  // image down = world down
  world_from_cam.col(0) = world_from_cam.col(1).cross(world_from_cam.col(2));  // right
  const Rigid3 cam_from_world = Rigid3(world_from_cam, camera).Inverse();
  const auto corners = marker.CornersInWorld();
  const Eigen::Vector3d top_left = cam_from_world * corners[0];
  const Eigen::Vector3d bottom_right = cam_from_world * corners[2];
  EXPECT_GT(top_left.z(), 0.0);
  EXPECT_LT(top_left.x(), 0.0);  // left of the optical axis
  EXPECT_LT(top_left.y(), 0.0);  // above it
  EXPECT_GT(bottom_right.x(), 0.0);
  EXPECT_GT(bottom_right.y(), 0.0);
}

TEST(LognavImportTest, ImportsAValidList) {
  const std::string text = R"([
    {"id": 1, "pos_x": -4.0, "pos_y": 0.6, "pos_z": 1.0, "yaw": -1.58, "size": 10.0},
    {"id": 12, "pos_x": 0.2, "pos_y": -3.5, "pos_z": 2, "yaw": 1.58, "size": 25}
  ])";
  LognavImportOptions options;
  options.dictionary = "DICT_5X5_100";
  options.fixed = false;
  const MarkerMap map = ParseLognavMarkers(text, "list.json", options);
  EXPECT_EQ(map.dictionary, "DICT_5X5_100");
  ASSERT_EQ(map.markers.size(), 2u);
  const MarkerInfo& first = map.markers.at(1);
  EXPECT_DOUBLE_EQ(first.size, 0.10);
  EXPECT_FALSE(first.fixed);
  EXPECT_EQ(first.world_from_marker.translation, Eigen::Vector3d(-4.0, 0.6, 1.0));
  const MarkerInfo& second = map.markers.at(12);
  EXPECT_DOUBLE_EQ(second.size, 0.25);
  EXPECT_EQ(second.world_from_marker.translation, Eigen::Vector3d(0.2, -3.5, 2.0));
  // Marker y is world up for every vertical marker.
  EXPECT_LT((second.world_from_marker.RotationMatrix().col(1) - Eigen::Vector3d::UnitZ()).norm(),
            1e-12);
  EXPECT_TRUE(ParseLognavMarkers("[]", "empty.json").markers.empty());
}

TEST(LognavImportTest, RejectsMalformedLists) {
  ExpectRejected("[{\"id\": 1,", {"not valid JSON"});
  ExpectRejected("{\"id\": 1}", {"expected a JSON array"});
  ExpectRejected("[3]", {"entry 0", "expected an object"});
  ExpectRejected(R"([{"id": 1, "pos_x": 0, "pos_y": 0, "pos_z": 1, "size": 10}])",
                 {"entry 0 (id 1)", "missing key 'yaw'"});
  ExpectRejected(
      R"([{"id": 1, "pos_x": 0, "pos_y": 0, "pos_z": 1, "yaw": 0, "size": 10, "roll": 0}])",
      {"entry 0 (id 1)", "unknown key 'roll'"});
  ExpectRejected(R"([{"id": "1", "pos_x": 0, "pos_y": 0, "pos_z": 1, "yaw": 0, "size": 10}])",
                 {"entry 0", "'id' must be an integer in 0..49", "\"1\""});
  ExpectRejected(R"([{"id": 50, "pos_x": 0, "pos_y": 0, "pos_z": 1, "yaw": 0, "size": 10}])",
                 {"'id' must be an integer in 0..49, found 50"});
  ExpectRejected(R"([{"id": 2, "pos_x": "a", "pos_y": 0, "pos_z": 1, "yaw": 0, "size": 10}])",
                 {"entry 0 (id 2)", "'pos_x' must be a finite number"});
  ExpectRejected(R"([{"id": 2, "pos_x": 0, "pos_y": 0, "pos_z": 1, "yaw": 0, "size": -10}])",
                 {"entry 0 (id 2)", "'size' must be positive"});
  ExpectRejected(R"([{"id": 2, "pos_x": 0, "pos_y": 0, "pos_z": 1, "yaw": 0, "size": 10},
                     {"id": 2, "pos_x": 1, "pos_y": 0, "pos_z": 1, "yaw": 0, "size": 10}])",
                 {"entry 1 (id 2): duplicate id 2 (also entry 0)"});
  LognavImportOptions options;
  options.dictionary = "DICT_3X3";
  EXPECT_THROW(ParseLognavMarkers("[]", "list.json", options), InputError);
}

// The authors' real file lists id 5 twice (entries 1 and 4).
TEST(LognavImportTest, RealFileIsRejectedForItsDuplicateId) {
  const std::filesystem::path path =
      std::filesystem::path(ARUCOSLAM_TEST_DATA_DIR) / "furg_lognav_markers" / "arucos_infos.json";
  if (!std::filesystem::exists(path)) {
    GTEST_SKIP() << "data set furg_lognav_markers not found at " << path;
  }
  try {
    ReadLognavMarkers(path);
    FAIL() << "the duplicate id 5 was accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), path.string());
    EXPECT_EQ(error.message(),
              "entry 4 (id 5): duplicate id 5 (also entry 1); give each marker its own id");
  }
}

}  // namespace
}  // namespace arucoslam
