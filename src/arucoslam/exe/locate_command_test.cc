// Runs `arucoslam locate` on rendered and real images and checks its pose, its JSON and how
// it fails.
#include <gtest/gtest.h>

#include "arucoslam/exe/command_test_util.h"
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <tuple>

#include "arucoslam/io/calibration.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/markers/synthetic_view.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

using RunResult = testing_util::SplitCommandResult;

class LocateCommandTest : public ::testing::Test {
 protected:
  RunResult Run(const std::string& arguments) const {
    return testing_util::RunArucoslamSplit(arguments, folder_);
  }

  static CameraModel Camera() {
    return PinholeCamera(640, 480, 500.0);
  }

  // Two 0.2 m markers (ids 3 and 8) on a wall 2 m ahead of a camera at a known world pose;
  // writes image.png, camera.yaml and markers.json (only `mapped_ids` in the map).
  Rigid3 WriteScene(const std::vector<int>& mapped_ids) const {
    const Rigid3 world_from_cam(
        Eigen::Quaterniond(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX())),
        Eigen::Vector3d(1.0, -2.0, 0.8));  // looking along world +y, z up
    // The two markers face the camera from two different wall angles.
    std::vector<std::pair<int, Rigid3>> placed;
    for (const auto& [id, yaw, position] :
         {std::tuple{3, 0.35, Eigen::Vector3d(-0.5, 0.15, 2.0)},
          std::tuple{8, -0.35, Eigen::Vector3d(0.5, -0.1, 2.2)}}) {
      placed.emplace_back(id,
                          Rigid3(Eigen::Matrix3d(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
                                                 Eigen::Vector3d(1, -1, -1).asDiagonal()),
                                 position));
    }
    std::vector<SyntheticMarker> markers;
    MarkerMap map;
    for (const auto& [id, cam_from_marker] : placed) {
      SyntheticMarker marker;
      marker.id = id;
      marker.cam_from_marker = cam_from_marker;
      markers.push_back(marker);
      if (std::find(mapped_ids.begin(), mapped_ids.end(), id) == mapped_ids.end()) continue;
      MarkerInfo info;
      info.id = id;
      info.size = 0.2;
      info.world_from_marker = world_from_cam * marker.cam_from_marker;
      map.markers[id] = info;
    }
    cv::imwrite((folder_ / "image.png").string(), RenderSyntheticView(Camera(), markers, {}));
    WriteEuRoCSensorYaml(Camera(), folder_ / "camera.yaml");
    WriteMarkerMapJson(map, folder_ / "markers.json");
    return world_from_cam;
  }

  std::string Args(const std::string& extra = "") const {
    return ArgsWithImage(folder_ / "image.png") + extra;
  }
  std::string ArgsWithImage(const fs::path& image) const {
    return "locate --image " + image.string() + " --camera " + (folder_ / "camera.yaml").string() +
           " --markers " + (folder_ / "markers.json").string();
  }

  ScratchFolder scratch_{"locate_command_test"};
  const fs::path& folder_ = scratch_.path();
};

Eigen::Vector3d Position(const nlohmann::json& pose) {
  return {pose["position"]["x"].get<double>(), pose["position"]["y"].get<double>(),
          pose["position"]["z"].get<double>()};
}

TEST_F(LocateCommandTest, JsonPoseFromTwoMarkersMatchesTruth) {
  const Rigid3 truth = WriteScene({3, 8});
  const RunResult result = Run(Args(" --json"));
  ASSERT_EQ(result.status, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_TRUE(json["found"].get<bool>());
  EXPECT_EQ(json["markers_used"], nlohmann::json::array({3, 8}));
  EXPECT_EQ(json["quality"]["num_markers"], 2);
  EXPECT_FALSE(json["quality"]["ambiguous"].get<bool>());
  // Distance about 2 m: within 1% of it.
  EXPECT_LT((Position(json["world_from_cam"]) - truth.translation).norm(), 0.02);
  const auto& o = json["world_from_cam"]["orientation"];
  const Eigen::Quaterniond q(o["w"].get<double>(), o["x"].get<double>(), o["y"].get<double>(),
                             o["z"].get<double>());
  EXPECT_LT(RotationAngle(q.inverse() * truth.rotation), 1.0 * M_PI / 180.0);
}

TEST_F(LocateCommandTest, TextOutputNamesMarkersUsedAndUnknown) {
  WriteScene({8});
  const RunResult result = Run(Args());
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("world_from_cam position (m):"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("markers used: 8 "), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("unknown markers: 3"), std::string::npos) << result.out;
}

TEST_F(LocateCommandTest, NoKnownMarkerExitsOneWithAReason) {
  WriteScene({});
  const RunResult result = Run(Args(" --json"));
  EXPECT_EQ(result.status, 1);
  const nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_FALSE(json["found"].get<bool>());
  EXPECT_EQ(json["failure"], "no known marker detected");
  EXPECT_EQ(json["unknown_markers"], nlohmann::json::array({3, 8}));
}

TEST_F(LocateCommandTest, BadInputIsOneLineAndStatusTwo) {
  WriteScene({3});
  for (const std::string& arguments :
       {ArgsWithImage(folder_ / "missing.png"), ArgsWithImage(folder_ / "camera.yaml"),
        ArgsWithImage(folder_), Args(" --refinement sharp")}) {
    const RunResult result = Run(arguments);
    EXPECT_EQ(result.status, 2) << arguments;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_EQ(result.err.rfind("arucoslam: ", 0), 0u) << result.err;
  }
  // An image of another size than the calibration's.
  cv::imwrite((folder_ / "image.png").string(), cv::Mat(240, 320, CV_8U, cv::Scalar(128)));
  const RunResult result = Run(Args());
  EXPECT_EQ(result.status, 2);
  EXPECT_NE(result.err.find("320x240"), std::string::npos) << result.err;
}

// Real photo 403.jpg (fiducials_aruco_unit) with its own calibration file: marker 403 at the
// world origin, so world_from_cam = marker_from_cam; the peer's expectation gives it via
// base_link (see expected.json): marker_from_cam = (base_from_marker)^-1 * base_from_cam.
TEST_F(LocateCommandTest, RealPhoto403AgreesWithPeer) {
  const fs::path dir = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "fiducials_aruco_unit";
  if (!fs::exists(dir / "images/403.jpg")) GTEST_SKIP() << "test data folder missing: " << dir;
  MarkerMap map;
  map.dictionary = "DICT_5X5_1000";
  MarkerInfo info;
  info.id = 403;
  info.size = 0.145;
  map.markers[403] = info;
  WriteMarkerMapJson(map, folder_ / "markers.json");
  const RunResult result = Run("locate --json --image " + (dir / "images/403.jpg").string() +
                               " --camera " + (dir / "camera_test_images.yaml").string() +
                               " --markers " + (folder_ / "markers.json").string());
  ASSERT_EQ(result.status, 0) << result.err;
  const nlohmann::json json = nlohmann::json::parse(result.out);
  const auto rpy = [](double roll, double pitch, double yaw) {
    return Eigen::Matrix3d(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                           Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                           Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
  };
  const Rigid3 base_from_cam(rpy(-1.204205, -0.041544, -1.479119),
                             Eigen::Vector3d(0.035, 0.145, 0.14));
  const Rigid3 base_from_marker(rpy(1.5751, -0.014, -1.546),
                                Eigen::Vector3d(0.7611, 0.2505, 0.4028));
  const Rigid3 expected = base_from_marker.Inverse() * base_from_cam;
  EXPECT_LT((Position(json["world_from_cam"]) - expected.translation).norm(), 0.01);
}

}  // namespace
}  // namespace arucoslam
