// Runs the `arucoslam` binary's `run` subcommand on real and generated sequences and on bad
// input, checking exit statuses, the four output files and what they contain.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "arucoslam/exe/command_test_util.h"
#include "arucoslam/geometry/camera.h"
#include "arucoslam/io/calibration.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

using Outcome = testing_util::SplitCommandResult;

class RunCommandTest : public ::testing::Test {
 protected:
  Outcome Run(const std::string& arguments) const {
    return testing_util::RunArucoslamSplit(arguments, dir_);
  }

  ScratchFolder scratch_{"run_test"};
  const fs::path& dir_ = scratch_.path();
};

int CountLines(const std::string& text, char skip_prefix) {
  int count = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    const std::string line = text.substr(start, end - start);
    if (!line.empty() && line[0] != skip_prefix) ++count;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return count;
}

TEST_F(RunCommandTest, RealStaticEurocSequenceWritesOutputsWithoutAMap) {
  const fs::path data = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro";
  if (!fs::exists(data)) GTEST_SKIP() << "test data missing: " << data;
  const fs::path out = dir_ / "out";
  const Outcome outcome = Run("run --dataset " + data.string() + " --out " + out.string() + " --blocking");
  ASSERT_EQ(outcome.status, 0) << outcome.err;
  for (const char* name : {"trajectory.tum", "online.tum", "keyframes.tum", "map.ply", "stats.json"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }
  // A camera standing still gives no map: no pose, no keyframe, no point.
  EXPECT_EQ(CountLines(ReadTextFile(out / "trajectory.tum"), '#'), 0);
  EXPECT_EQ(CountLines(ReadTextFile(out / "keyframes.tum"), '#'), 0);
  EXPECT_NE(ReadTextFile(out / "map.ply").find("element vertex 0\n"), std::string::npos);
  const std::string stats = ReadTextFile(out / "stats.json");
  EXPECT_NE(stats.find("\"total\": 95"), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"initializations\": 0"), std::string::npos);
  EXPECT_NE(stats.find("\"median\""), std::string::npos);
  EXPECT_NE(stats.find("\"peak_memory_bytes\""), std::string::npos);
  EXPECT_NE(outcome.out.find("95 frames, 0 tracked"), std::string::npos) << outcome.out;
  EXPECT_NE(outcome.err.find("frame 95/95"), std::string::npos);  // the progress line
}

// --realtime replays the 95 frames (20 Hz, 4.7 s) as their camera delivered them: the run
// lasts at least the recording, and every frame is either processed or counted as dropped.
TEST_F(RunCommandTest, RealtimeReplayTakesTheRecordingsTimeAndCountsDroppedFrames) {
  const fs::path data = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro";
  if (!fs::exists(data)) GTEST_SKIP() << "test data missing: " << data;
  const fs::path out = dir_ / "out";
  const Outcome outcome =
      Run("run --dataset " + data.string() + " --out " + out.string() + " --realtime --quiet");
  ASSERT_EQ(outcome.status, 0) << outcome.err;
  const nlohmann::json stats = nlohmann::json::parse(ReadTextFile(out / "stats.json"));
  const int total = stats["frames"]["total"].get<int>();
  EXPECT_EQ(total + stats["frames"]["dropped"].get<int>(), 95) << stats.dump();
  EXPECT_GE(total, 1);
  EXPECT_GE(stats["wall_time_s"].get<double>(), 4.7);
  EXPECT_EQ(Run("run --dataset " + data.string() + " --device 0 --realtime --out " +
                (dir_ / "x").string()).status, 2);
}

// An image folder of a textured plane 2 m in front of a camera sliding sideways (images
// made by warping a real EuRoC frame with the plane's homography), with its calibration.
fs::path MakePlaneSequence(const fs::path& dir, int num_frames) {
  const fs::path source = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro/mav0/cam0/data";
  fs::path first;
  for (const auto& entry : fs::directory_iterator(source)) {
    if (first.empty() || entry.path() < first) first = entry.path();
  }
  const cv::Mat texture = cv::imread(first.string(), cv::IMREAD_GRAYSCALE);
  const CameraModel camera = PinholeCamera(640, 480, 450.0);
  const fs::path images = dir / "images";
  fs::create_directories(images);
  WriteEuRoCSensorYaml(camera, dir / "camera.yaml");
  const Eigen::Matrix3d k = (Eigen::Matrix3d() << 450, 0, 319.5, 0, 450, 239.5, 0, 0, 1).finished();
  // Plane z = 2 in the first camera; camera t at x = 0.02 t metres: pixels shift by
  // fx * x / 2 = 4.5 px per frame. The texture is shown at 1.3x to fill the view.
  for (int t = 0; t < num_frames; ++t) {
    const double x = 0.02 * t;
    Eigen::Matrix3d texture_to_cam0 = Eigen::Matrix3d::Identity();
    texture_to_cam0(0, 0) = texture_to_cam0(1, 1) = 1.3;
    texture_to_cam0(0, 2) = 319.5 - 1.3 * texture.cols / 2.0;
    texture_to_cam0(1, 2) = 239.5 - 1.3 * texture.rows / 2.0;
    Eigen::Matrix3d shift = Eigen::Matrix3d::Identity();
    shift(0, 2) = -450.0 * x / 2.0;
    const Eigen::Matrix3d h = shift * texture_to_cam0;
    cv::Mat h_cv(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) h_cv.at<double>(r, c) = h(r, c);
    }
    cv::Mat image;
    cv::warpPerspective(texture, image, h_cv, cv::Size(640, 480), cv::INTER_LINEAR,
                        cv::BORDER_REFLECT);
    char name[32];
    std::snprintf(name, sizeof(name), "%04d.png", t);
    cv::imwrite((images / name).string(), image);
  }
  (void)k;
  return images;
}

TEST_F(RunCommandTest, MovingCameraOverPlaneIsTracked) {
  if (!fs::exists(fs::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro")) {
    GTEST_SKIP() << "test data missing: euroc_v101_micro";
  }
  const int num_frames = 40;
  const fs::path images = MakePlaneSequence(dir_, num_frames);
  const fs::path out = dir_ / "out";
  const Outcome outcome = Run("run --dataset " + images.string() + " --camera " +
                              (dir_ / "camera.yaml").string() + " --rate 20 --out " +
                              out.string() + " --blocking --quiet");
  ASSERT_EQ(outcome.status, 0) << outcome.err;
  const Trajectory trajectory = ReadTumTrajectory(out / "trajectory.tum");
  ASSERT_GE(trajectory.size(), 30u) << outcome.out;
  // Sideways motion: the direction of travel is the camera's x axis, the same in every frame.
  const Eigen::Vector3d travel =
      trajectory.poses.back().translation - trajectory.poses.front().translation;
  const Eigen::Vector3d x_axis = trajectory.poses.front().rotation * Eigen::Vector3d::UnitX();
  EXPECT_GT(std::abs(travel.normalized().dot(x_axis)), 0.98);
  EXPECT_GE(ReadTumTrajectory(out / "keyframes.tum").size(), 2u);
  // Without markers each tracked frame's pose as it was tracked (the backfilled ones not), in
  // the map's own frame.
  const Trajectory online = ReadTumTrajectory(out / "online.tum");
  EXPECT_GE(online.size(), static_cast<std::size_t>(num_frames / 2));
  EXPECT_EQ(outcome.err.find("\rframe"), std::string::npos);  // --quiet
}

TEST_F(RunCommandTest, MissingOrCorruptVocabularyIsOneLineAndExitTwo) {
  if (!fs::exists(fs::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro")) {
    GTEST_SKIP() << "test data missing: euroc_v101_micro";
  }
  const fs::path images = MakePlaneSequence(dir_, 3);
  const fs::path out = dir_ / "out";
  const std::string run = "run --dataset " + images.string() + " --camera " +
                          (dir_ / "camera.yaml").string() + " --rate 20 --out " + out.string();
  Outcome outcome = Run(run + " --vocabulary " + (dir_ / "none.bin").string());
  EXPECT_EQ(outcome.status, 2);
  EXPECT_NE(outcome.err.find("none.bin"), std::string::npos) << outcome.err;
  EXPECT_EQ(CountLines(outcome.err, '\0'), 1) << outcome.err;
  WriteTextFileAtomically(dir_ / "corrupt.bin", "not a vocabulary");
  outcome = Run(run + " --vocabulary " + (dir_ / "corrupt.bin").string());
  EXPECT_EQ(outcome.status, 2);
  EXPECT_NE(outcome.err.find("corrupt.bin"), std::string::npos) << outcome.err;
  EXPECT_EQ(CountLines(outcome.err, '\0'), 1) << outcome.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(RunCommandTest, BadInputIsOneLineAndExitTwo) {
  const fs::path out = dir_ / "out";
  Outcome outcome = Run("run --dataset " + (dir_ / "missing").string() + " --out " + out.string());
  EXPECT_EQ(outcome.status, 2);
  EXPECT_NE(outcome.err.find("missing"), std::string::npos) << outcome.err;
  EXPECT_EQ(CountLines(outcome.err, '\0'), 1) << outcome.err;
  EXPECT_FALSE(fs::exists(out));
  // An image folder needs a calibration.
  fs::create_directories(dir_ / "images");
  cv::imwrite((dir_ / "images/0000.png").string(), cv::Mat(480, 640, CV_8U, cv::Scalar(128)));
  outcome = Run("run --dataset " + (dir_ / "images").string() + " --out " + out.string());
  EXPECT_EQ(outcome.status, 2) << outcome.err;
  EXPECT_FALSE(fs::exists(out));
  // --out names a file.
  WriteTextFileAtomically(dir_ / "file", "x");
  const fs::path data = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro";
  if (fs::exists(data)) {
    outcome = Run("run --dataset " + data.string() + " --out " + (dir_ / "file").string());
    EXPECT_EQ(outcome.status, 2);
    EXPECT_NE(outcome.err.find("not a directory"), std::string::npos) << outcome.err;
  }
  outcome = Run("run --dataset " + data.string() + " --out " + out.string() + " --features 5");
  EXPECT_EQ(outcome.status, 2);
  EXPECT_NE(outcome.err.find("--features"), std::string::npos) << outcome.err;
  // The ground-vehicle prior is held in the marker world, and this image folder has no
  // markers.json.
  WriteEuRoCSensorYaml(PinholeCamera(640, 480, 500.0), dir_ / "sensor.yaml");
  outcome = Run("run --dataset " + (dir_ / "images").string() + " --camera " +
                (dir_ / "sensor.yaml").string() + " --out " + out.string() + " --ground-vehicle");
  EXPECT_EQ(outcome.status, 2);
  EXPECT_NE(outcome.err.find("--ground-vehicle: needs markers"), std::string::npos) << outcome.err;
  EXPECT_EQ(CountLines(outcome.err, '\0'), 1) << outcome.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(Run("run --out " + out.string()).status, 2);  // --dataset missing
}

TEST_F(RunCommandTest, MarkerMapIsWrittenToTheOutput) {
  const fs::path data = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro";
  if (!fs::exists(data)) GTEST_SKIP() << "test data missing: " << data;
  MarkerMap known;
  MarkerInfo info;
  info.id = 7;
  info.size = 0.25;
  info.world_from_marker = Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1.0, 2.0, 3.0));
  known.markers[7] = info;
  WriteMarkerMapJson(known, dir_ / "known.json");
  const fs::path out = dir_ / "out";
  const Outcome outcome = Run("run --dataset " + data.string() + " --markers " +
                              (dir_ / "known.json").string() + " --marker-size 0.3 --out " +
                              out.string() + " --blocking --quiet");
  ASSERT_EQ(outcome.status, 0) << outcome.err;
  // The camera stands still: nothing is mapped, the known marker comes back as it was.
  const MarkerMap written = ReadMarkerMapJson(out / "markers.json");
  ASSERT_EQ(written.markers.size(), 1u);
  EXPECT_TRUE(written.markers.at(7).fixed);
  EXPECT_DOUBLE_EQ(written.markers.at(7).size, 0.25);
  EXPECT_NEAR(written.markers.at(7).world_from_marker.translation.y(), 2.0, 1e-9);

  const Outcome bad = Run("run --dataset " + data.string() + " --markers " +
                          (dir_ / "known.json").string() + " --marker-size -1 --out " +
                          (dir_ / "out2").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--marker-size"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir_ / "out2"));
  const Outcome missing = Run("run --dataset " + data.string() + " --markers " +
                              (dir_ / "none.json").string() + " --out " + (dir_ / "out3").string());
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("none.json"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace arucoslam
