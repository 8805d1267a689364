// Runs the `arucoslam markers ...` binary and checks what it writes and how it fails.
#include <gtest/gtest.h>

#include "arucoslam/exe/command_test_util.h"
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/aruco.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sdf/Model.hh>
#include <sdf/ParserConfig.hh>
#include <sdf/Root.hh>
#include <sdf/World.hh>

#include "arucoslam/io/lognav_import.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/markers/dictionary.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

using RunResult = testing_util::SplitCommandResult;

class MarkersCommandTest : public ::testing::Test {
 protected:
  RunResult Run(const std::string& arguments) const {
    return testing_util::RunArucoslamSplit(arguments, folder_);
  }

  ScratchFolder scratch_{"markers_command_test"};
  const fs::path& folder_ = scratch_.path();
};

TEST_F(MarkersCommandTest, GenerateWritesDetectableMarkersAndAValidTemplate) {
  const fs::path out = folder_ / "gen";
  const RunResult run =
      Run("markers generate --dictionary DICT_6X6_250 --ids 0-2,40 "
          "--size-px 300 --size 0.25 --out " +
          out.string());
  ASSERT_EQ(run.status, 0) << run.err;
  const cv::Ptr<cv::aruco::Dictionary> dictionary = DictionaryFromName("DICT_6X6_250");
  for (const int id : {0, 1, 2, 40}) {
    const cv::Mat image = cv::imread((out / ("marker_" + std::to_string(id) + ".png")).string(),
                                     cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty()) << id;
    EXPECT_EQ(image.cols, 300 + 2 * 75);  // 8 cells of 37.5 px, quiet zone 2 cells
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::aruco::detectMarkers(image, dictionary, corners, ids);
    ASSERT_EQ(ids.size(), 1u) << id;
    EXPECT_EQ(ids[0], id);
    // Top-left corner of the black square at the quiet zone's inner edge.
    EXPECT_NEAR(corners[0][0].x, 74.5, 1.0);
    EXPECT_NEAR(corners[0][0].y, 74.5, 1.0);
  }
  const MarkerMap map = ReadMarkerMapJson(out / "markers.json");
  EXPECT_EQ(map.dictionary, "DICT_6X6_250");
  ASSERT_EQ(map.markers.size(), 4u);
  for (const auto& [id, marker] : map.markers) {
    EXPECT_EQ(marker.size, 0.25);
    EXPECT_TRUE(marker.fixed);
  }
  // Placeholder poses two box sides (0.25 * 450 / 300 m) apart along x.
  EXPECT_NEAR(map.markers.at(40).world_from_marker.translation.x(), 3 * 2 * 0.375, 1e-12);
}

TEST_F(MarkersCommandTest, GenerateRejectsBadOptionsWithoutWriting) {
  const fs::path out = folder_ / "gen";
  RunResult run = Run("markers generate --dictionary DICT_4X4_51 --ids 0-3 --out " + out.string());
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.err.rfind("arucoslam: --dictionary: unknown marker dictionary 'DICT_4X4_51'", 0),
            0u)
      << run.err;
  run = Run("markers generate --ids 0-3,2 --out " + out.string());
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.err, "arucoslam: --ids: id 2 is listed twice\n");
  run = Run("markers generate --ids 48-52 --out " + out.string());
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.err, "arucoslam: --ids: id 50 is outside DICT_4X4_50 (0..49)\n");
  run = Run("markers generate --ids 0 --size -1 --out " + out.string());
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.err.find("--size"), std::string::npos) << run.err;
  run = Run("markers generate --out " + out.string());
  EXPECT_EQ(run.status, 2);
  EXPECT_NE(run.err.find("--ids"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(MarkersCommandTest, SdfWorldParsesBackWithTheJsonPoses) {
  MarkerMap map;
  map.dictionary = "DICT_4X4_50";
  const Eigen::Quaterniond q1(0.3, -0.2, 0.9, 0.1);
  map.markers[3] = MarkerInfo{3, 0.2, Rigid3(q1, Eigen::Vector3d(4.0, 1.5, 0.8)), true};
  const Eigen::Quaterniond q2(0.5, 0.5, 0.5, 0.5);
  map.markers[9] = MarkerInfo{9, 0.1, Rigid3(q2, Eigen::Vector3d(-1.0 / 3, 2.0, 1.2)), false};
  map.markers[12] = MarkerInfo{12, 0.15, LognavWorldFromMarker(-4, 0.6, 1, -1.58), true};
  WriteMarkerMapJson(map, folder_ / "markers.json");
  const fs::path out = folder_ / "world";
  const RunResult run = Run("markers sdf --size-px 60 --markers " +
                            (folder_ / "markers.json").string() + " --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.err;

  sdf::ParserConfig config;
  config.AddURIPath("model://", out.string());
  sdf::Root root;
  const sdf::Errors errors = root.Load((out / "world.sdf").string(), config);
  for (const sdf::Error& error : errors) ADD_FAILURE() << error.Message();
  ASSERT_EQ(root.WorldCount(), 1u);
  const sdf::World* world = root.WorldByIndex(0);
  ASSERT_EQ(world->ModelCount(), 3u);
  for (const auto& [id, marker] : map.markers) {
    const sdf::Model* model = world->ModelByName("marker_" + std::to_string(id));
    ASSERT_NE(model, nullptr) << id;
    const ignition::math::Pose3d pose = model->RawPose();
    const Eigen::Vector3d position(pose.Pos().X(), pose.Pos().Y(), pose.Pos().Z());
    EXPECT_LT((position - marker.world_from_marker.translation).norm(), 1e-9) << id;
    const Eigen::Quaterniond rotation(pose.Rot().W(), pose.Rot().X(), pose.Rot().Y(),
                                      pose.Rot().Z());
    EXPECT_LT(RotationAngle(rotation.inverse() * marker.world_from_marker.rotation), 1e-9) << id;
    EXPECT_TRUE(fs::exists(out / ("marker_" + std::to_string(id)) /
                           ("marker_" + std::to_string(id) + ".png")));
  }
  EXPECT_EQ(MarkerMapToJson(ReadMarkerMapJson(out / "markers.json")), MarkerMapToJson(map));
}

TEST_F(MarkersCommandTest, SdfRejectsAMalformedMapWithOneLine) {
  {
    std::ofstream file(folder_ / "markers.json");
    file << R"({"format": "arucoslam.markers/1", "dictionary": "DICT_4X4_50", "frame": "world",
                "markers": [{"id": 1, "size": 0.2, "pose": {"position": {"x": 0, "y": 0, "z": 0},
                "orientation": {"x": 0, "y": 0, "z": 0, "w": 2}}, "fixed": true,
                "corners": [[-0.1, 0.1, 0], [0.1, 0.1, 0], [0.1, -0.1, 0], [-0.1, -0.1, 0]]}]})";
  }
  const fs::path out = folder_ / "world";
  const RunResult run = Run("markers sdf --markers " + (folder_ / "markers.json").string() +
                            " --out " + out.string());
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.err, "arucoslam: " + (folder_ / "markers.json").string() +
                         ": markers[0].pose.orientation: quaternion norm 2.000000 is not 1 "
                         "(tolerance 1e-6)\n");
  EXPECT_FALSE(fs::exists(out));
  const RunResult missing =
      Run("markers sdf --markers " + (folder_ / "absent.json").string() + " --out " + out.string());
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("absent.json"), std::string::npos) << missing.err;
}

TEST_F(MarkersCommandTest, ImportConvertsAValidList) {
  {
    std::ofstream file(folder_ / "list.json");
    file << R"([{"id": 4, "pos_x": 0.2, "pos_y": -3.5, "pos_z": 1.0, "yaw": 1.58, "size": 10.0},
               {"id": 1, "pos_x": -4.0, "pos_y": 0.6, "pos_z": 1.0, "yaw": -1.58, "size": 20}])";
  }
  const fs::path out = folder_ / "markers.json";
  const RunResult run =
      Run("markers import --lognav " + (folder_ / "list.json").string() + " --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.err;
  const MarkerMap map = ReadMarkerMapJson(out);
  EXPECT_EQ(map.dictionary, "DICT_4X4_50");
  ASSERT_EQ(map.markers.size(), 2u);
  EXPECT_EQ(map.markers.at(1).size, 0.2);
  const Rigid3 expected = LognavWorldFromMarker(0.2, -3.5, 1.0, 1.58);
  EXPECT_EQ(map.markers.at(4).world_from_marker.translation, expected.translation);
  EXPECT_LT(
      RotationAngle(map.markers.at(4).world_from_marker.rotation.inverse() * expected.rotation),
      1e-15);
}

TEST_F(MarkersCommandTest, ImportRejectsTheRealFileForItsDuplicateId) {
  const fs::path path =
      fs::path(ARUCOSLAM_TEST_DATA_DIR) / "furg_lognav_markers" / "arucos_infos.json";
  if (!fs::exists(path)) GTEST_SKIP() << "data set furg_lognav_markers not found at " << path;
  const fs::path out = folder_ / "markers.json";
  const RunResult run = Run("markers import --lognav " + path.string() + " --out " + out.string());
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.err, "arucoslam: " + path.string() +
                         ": entry 4 (id 5): duplicate id 5 (also entry 1); give each marker "
                         "its own id\n");
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace arucoslam
