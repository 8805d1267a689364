// `arucoslam run` map reuse end to end: a map saved from one rendered sequence of a factory
// world is loaded for a second sequence of the same world that starts 3 m further along the
// aisle; localisation-only, without markers, must localise in the saved (marker world) map.
// Also the bad map files and option combinations (one line, exit 2, nothing written).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include "arucoslam/exe/aisle_sequence_test_util.h"
#include "arucoslam/exe/command_test_util.h"
#include "arucoslam/io/map_file.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;
using testing_util::RunArucoslamSplit;
using testing_util::SplitCommandResult;

class RunMapReuseTest : public ::testing::Test {
 protected:
  // A one-aisle factory; sequence A drives the aisle from x = 6 m to 12.5 m (teach run), B
  // from x = 9 m to 12.5 m (repeat run: up to 8 cm off to the side), both 15 Hz, 320x240
  // (the default camera at half size), no MSAA.
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("arucoslam_map_reuse_test_" + std::to_string(getpid()));
    SplitCommandResult result = testing_util::MakeAisleTeachSequence(dir_);
    ASSERT_EQ(result.status, 0) << result.err;
    result = testing_util::SimulateAisle(dir_, "b", 9.0, "repeat");
    ASSERT_EQ(result.status, 0) << result.err;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static SplitCommandResult Run(const std::string& arguments) {
    return RunArucoslamSplit(arguments, dir_);
  }
  static std::string RunArgs(const std::string& sequence, const std::string& out) {
    return "run --dataset " + (dir_ / sequence).string() + " --out " + (dir_ / out).string() +
           " --blocking --quiet";
  }

  static fs::path dir_;
};

fs::path RunMapReuseTest::dir_;

// Ground-truth camera positions of a sequence by timestamp (seconds).
std::map<double, Eigen::Vector3d> TruePositions(const fs::path& sequence) {
  const Trajectory truth =
      ReadEurocTrajectory(sequence / "mav0" / "state_groundtruth_estimate0" / "data.csv");
  std::map<double, Eigen::Vector3d> positions;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    positions[truth.timestamps[i]] = truth.poses[i].translation;
  }
  return positions;
}

TEST_F(RunMapReuseTest, SavedMapLocalisesASequenceStartingElsewhere) {
  const fs::path map_file = dir_ / "aisle.map";
  SplitCommandResult result = Run(RunArgs("seq_a", "run_a") + " --save-map " + map_file.string());
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("map saved to " + map_file.string()), std::string::npos)
      << result.out;
  MapFileInfo info;
  const MapData saved = LoadMapFile(map_file, &info);
  EXPECT_TRUE(info.world_aligned);  // sequence A sees the markers: metric, world frame
  ASSERT_GE(saved.NumKeyframes(), 5u);

  // Sequence B, keypoints only (--no-markers), against the saved map.
  result = Run(RunArgs("seq_b", "run_b") + " --no-markers --load-map " + map_file.string() +
               " --localize-only");
  ASSERT_EQ(result.status, 0) << result.err;
  const Trajectory estimate = ReadTumTrajectory(dir_ / "run_b" / "trajectory.tum");
  const std::map<double, Eigen::Vector3d> truth = TruePositions(dir_ / "seq_b");
  // Localised from the first frame on: measured 83 poses for 83 frames.
  EXPECT_GE(static_cast<double>(estimate.size()), 0.95 * truth.size()) << result.out;
  ASSERT_FALSE(estimate.empty());
  EXPECT_LE(estimate.timestamps.front() - truth.begin()->first, 1.0);
  // In the saved map's world frame, no alignment: measured 0.061 m RMS (max 0.11 m), about
  // the error of sequence A's own poses over the same stretch (its world alignment, from
  // 0.3 m markers 3-9 m away, is off by 0.05-0.13 m there).
  double sum = 0.0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const auto it = truth.lower_bound(estimate.timestamps[i] - 1e-3);
    ASSERT_TRUE(it != truth.end() && it->first < estimate.timestamps[i] + 1e-3)
        << estimate.timestamps[i];
    sum += (estimate.poses[i].translation - it->second).squaredNorm();
  }
  EXPECT_LT(std::sqrt(sum / estimate.size()), 0.2);
  // The map is not changed: the same keyframes at the same poses.
  const Trajectory keyframes_b = ReadTumTrajectory(dir_ / "run_b" / "keyframes.tum");
  const Trajectory keyframes_a = ReadTumTrajectory(dir_ / "run_a" / "keyframes.tum");
  ASSERT_EQ(keyframes_b.size(), saved.NumKeyframes());
  ASSERT_EQ(keyframes_b.size(), keyframes_a.size());
  for (std::size_t i = 0; i < keyframes_a.size(); ++i) {
    EXPECT_LT((keyframes_a.poses[i].translation - keyframes_b.poses[i].translation).norm(), 1e-6);
  }
  const std::string stats = ReadTextFile(dir_ / "run_b" / "stats.json");
  EXPECT_NE(stats.find("\"keyframes_inserted\": 0"), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"initializations\": 0"), std::string::npos) << stats;
  EXPECT_EQ(stats.find("\"relocalisations\": 0"), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"points\": " + std::to_string(saved.NumMapPoints())), std::string::npos)
      << stats;
}

TEST_F(RunMapReuseTest, BadMapFilesAndOptionsAreOneLineAndExitTwo) {
  const std::string bytes = SerializeMap(MapData());
  WriteTextFileAtomically(dir_ / "empty.map", bytes);
  WriteTextFileAtomically(dir_ / "truncated.map", bytes.substr(0, bytes.size() - 5));
  std::string old_version = bytes;
  old_version[20] = 1;  // the format version field
  WriteTextFileAtomically(dir_ / "old.map", old_version);
  WriteTextFileAtomically(dir_ / "text.map", "keyframes: 3\n");
  const std::string base = RunArgs("seq_b", "bad_out");
  struct Case {
    std::string arguments;
    std::string expected;  // in the error line
  };
  const Case cases[] = {
      {base + " --load-map " + (dir_ / "absent.map").string(), "absent.map"},
      {base + " --load-map " + (dir_ / "truncated.map").string(),
       "truncated.map: truncated map file"},
      {base + " --load-map " + (dir_ / "old.map").string() + " --localize-only",
       "old.map: map format version 1, this build reads 2"},
      {base + " --load-map " + (dir_ / "text.map").string(), "not an arucoslam map"},
      {base + " --load-map " + (dir_ / "empty.map").string(), "the map has no keyframes"},
      {base + " --localize-only", "--localize-only"},
      {base + " --load-map " + (dir_ / "empty.map").string() + " --localize-only --save-map " +
           (dir_ / "new.map").string(),
       "--save-map"},
      {base + " --save-map " + (dir_ / "no_folder" / "new.map").string(), "no_folder"},
  };
  for (const Case& c : cases) {
    const SplitCommandResult result = Run(c.arguments);
    EXPECT_EQ(result.status, 2) << c.arguments << "\n" << result.err;
    EXPECT_NE(result.err.find(c.expected), std::string::npos) << c.arguments << "\n" << result.err;
    EXPECT_EQ(result.err.find('\n'), result.err.size() - 1) << result.err;
    EXPECT_FALSE(fs::exists(dir_ / "bad_out")) << c.arguments;
    EXPECT_FALSE(fs::exists(dir_ / "new.map")) << c.arguments;
    EXPECT_FALSE(fs::exists(dir_ / "no_folder")) << c.arguments;
  }
}

}  // namespace
}  // namespace arucoslam
