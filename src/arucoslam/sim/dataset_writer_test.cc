#include "arucoslam/sim/dataset_writer.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/markers/marker_image.h"
#include "arucoslam/sim/world_model.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

CameraModel SmallCamera() {
  CameraModel camera;
  camera.width = 320;
  camera.height = 240;
  camera.fx = camera.fy = 230.0;
  camera.cx = 159.5;
  camera.cy = 119.5;
  camera.rate_hz = 30.0;
  return camera;
}

// Camera 0.6 m above the floor driving along +x (camera z forward = world x).
std::vector<TimedPose> StraightDrive(int frames) {
  Eigen::Matrix3d cam_axes;  // columns: camera x, y, z in the world
  cam_axes << 0, 0, 1,  //
      -1, 0, 0,         //
      0, -1, 0;
  std::vector<TimedPose> poses;
  for (int i = 0; i < frames; ++i) {
    const double t = i / 30.0;
    poses.push_back({t, Rigid3(cam_axes, Eigen::Vector3d(0.5 * t, 0.02 * t, 0.6))});
  }
  return poses;
}

class DatasetWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arucoslam_dataset_writer_test_" + std::to_string(getpid()));
    fs::create_directories(dir_ / "world" / "textures");
    cv::imwrite((dir_ / "world" / "textures" / "marker_3.png").string(),
                DrawMarkerImage("DICT_4X4_50", 3, MarkerImageOptions{200, 2.0}));
    cv::Mat floor(64, 64, CV_8UC3);
    cv::randu(floor, 90, 140);
    cv::imwrite((dir_ / "world" / "textures" / "floor.png").string(), floor);
    std::ofstream(dir_ / "world" / "world.sdf") << R"(<?xml version="1.0"?>
<sdf version="1.9"><world name="w">
  <model name="floor"><static>true</static><link name="l"><visual name="v">
    <geometry><plane><normal>0 0 1</normal><size>20 20</size></plane></geometry>
    <material><pbr><metal><albedo_map>textures/floor.png</albedo_map></metal></pbr></material>
  </visual></link></model>
  <model name="wall"><static>true</static><pose>4 0 1 0 0 0</pose><link name="l"><visual name="v">
    <geometry><box><size>0.2 6 2</size></box></geometry>
    <material><diffuse>0.8 0.8 0.75 1</diffuse></material></visual></link></model>
  <model name="marker_3"><static>true</static><pose>3.899 0 0.6 0 -1.5707963267948966 0</pose>
    <link name="l"><visual name="v"><geometry><box><size>0.3 0.3 0.002</size></box></geometry>
    <material><pbr><metal><albedo_map>textures/marker_3.png</albedo_map></metal></pbr></material>
  </visual></link></model>
</world></sdf>)";
    std::ofstream(dir_ / "world" / "markers.json") << "{}";  // copied as it is
    options_.render.noise_sigma = 2.0;
    options_.exposure_time_s = 0.01;
    options_.write_depth = true;
    options_.progress = false;
  }
  void TearDown() override {
    if (std::getenv("ARUCOSLAM_KEEP_TEST_OUTPUT") == nullptr) fs::remove_all(dir_);
  }

  fs::path dir_;
  DatasetWriterOptions options_;
};

TEST_F(DatasetWriterTest, WritesEurocLayoutThatTheReaderLoads) {
  const std::vector<TimedPose> poses = StraightDrive(12);
  const DatasetSummary summary = WriteSimulatedSequence(dir_ / "world" / "world.sdf",
                                                        SmallCamera(), poses, dir_ / "seq", options_);
  EXPECT_EQ(summary.frames, 12u);
  EXPECT_NEAR(summary.duration_s, 11 / 30.0, 1e-12);
  const fs::path seq = dir_ / "seq";
  for (const char* file : {"world.sdf", "markers.json", "textures/marker_3.png",
                           "textures/floor.png", "mav0/cam0/sensor.yaml",
                           "mav0/depth0/data.csv"}) {
    EXPECT_TRUE(fs::is_regular_file(seq / file)) << file;
  }
  EXPECT_EQ(LoadWorldModel(seq / "world.sdf").primitives.size(), 3u);

  const Dataset dataset = Dataset::Open(seq);
  ASSERT_EQ(dataset.size(), 12u);
  EXPECT_EQ(dataset.camera().width, 320);
  EXPECT_DOUBLE_EQ(dataset.camera().fx, 230.0);
  EXPECT_EQ(dataset.frame(3).timestamp_ns, options_.start_time_ns + 100'000'000);
  ASSERT_EQ(dataset.ground_truth().size(), 12u);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Rigid3& read = dataset.ground_truth().poses[i];
    EXPECT_LT((read.translation - poses[i].world_from_cam.translation).norm(), 1e-8);
    EXPECT_LT(RotationAngle(read.rotation.inverse() * poses[i].world_from_cam.rotation), 1e-10);
  }
  const cv::Mat image = dataset.LoadImage(5);
  EXPECT_EQ(image.type(), CV_8UC1);
  // The wall ahead fills the centre: depth there is its distance along the optical axis.
  const cv::Mat depth = cv::imread(
      (seq / "mav0/depth0/data" / dataset.frame(0).image_path.filename()).string(),
      cv::IMREAD_UNCHANGED);
  ASSERT_EQ(depth.type(), CV_16UC1);
  EXPECT_NEAR(depth.at<std::uint16_t>(120, 100), 3900.0, 2.0);  // mm; the wall face x = 3.9
}

TEST_F(DatasetWriterTest, SameInputsGiveIdenticalImages) {
  const std::vector<TimedPose> poses = StraightDrive(4);
  WriteSimulatedSequence(dir_ / "world" / "world.sdf", SmallCamera(), poses, dir_ / "a", options_);
  WriteSimulatedSequence(dir_ / "world" / "world.sdf", SmallCamera(), poses, dir_ / "b", options_);
  for (const auto& entry : fs::directory_iterator(dir_ / "a" / "mav0" / "cam0" / "data")) {
    const fs::path other = dir_ / "b" / "mav0" / "cam0" / "data" / entry.path().filename();
    EXPECT_EQ(ReadTextFile(entry.path()), ReadTextFile(other)) << entry.path();
  }
  DatasetWriterOptions other_seed = options_;
  other_seed.render.noise_seed = 99;
  WriteSimulatedSequence(dir_ / "world" / "world.sdf", SmallCamera(), poses, dir_ / "c",
                         other_seed);
  const fs::path first = *fs::directory_iterator(dir_ / "a" / "mav0" / "cam0" / "data");
  EXPECT_NE(ReadTextFile(first), ReadTextFile(dir_ / "c" / "mav0" / "cam0" / "data" /
                                              first.filename()));
}

TEST_F(DatasetWriterTest, FailureLeavesNoOutput) {
  std::vector<TimedPose> poses = StraightDrive(6);
  poses[4].time_s = poses[2].time_s;  // time goes back
  EXPECT_THROW(WriteSimulatedSequence(dir_ / "world" / "world.sdf", SmallCamera(), poses,
                                      dir_ / "bad", options_),
               InputError);
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
  for (const auto& entry : fs::directory_iterator(dir_)) {
    EXPECT_EQ(entry.path().filename().string().find("bad"), std::string::npos) << entry.path();
  }
}

TEST(ExposurePosesTest, SpreadsOverTheWindowByInterpolation) {
  std::vector<TimedPose> poses;
  for (int i = 0; i < 3; ++i) {
    poses.push_back({i * 0.1, Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d::UnitZ())),
                                     Eigen::Vector3d(i, 0, 0))});
  }
  const std::vector<Rigid3> window = ExposurePoses(poses, 1, 0.1, 2);
  ASSERT_EQ(window.size(), 2u);
  // Samples at t = 0.075 and 0.125: x = 0.75 and 1.25, yaw 0.15 and 0.25.
  EXPECT_NEAR(window[0].translation.x(), 0.75, 1e-12);
  EXPECT_NEAR(window[1].translation.x(), 1.25, 1e-12);
  EXPECT_NEAR(RotationAngle(window[1].rotation), 0.25, 1e-12);
  // Clamped at the end of the path.
  EXPECT_NEAR(ExposurePoses(poses, 2, 0.1, 2)[1].translation.x(), 2.0, 1e-12);
  EXPECT_EQ(ExposurePoses(poses, 0, 0.0, 4).size(), 1u);
}

}  // namespace
}  // namespace arucoslam
