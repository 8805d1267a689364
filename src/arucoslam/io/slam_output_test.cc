#include "arucoslam/io/slam_output.h"

#include <gtest/gtest.h>

#include <sstream>

#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

TEST(SlamOutput, PlyHasHeaderAndEveryPointAtFullPrecision) {
  const std::vector<Eigen::Vector3d> points = {{1.0, -2.5, 3.25}, {0.123456789, 1e-3, -7.0}};
  const std::string text = FormatPlyPoints(points);
  EXPECT_NE(text.find("element vertex 2\n"), std::string::npos);
  std::istringstream in(text.substr(text.find("end_header\n") + 11));
  for (const Eigen::Vector3d& p : points) {
    Eigen::Vector3d read;
    ASSERT_TRUE(in >> read.x() >> read.y() >> read.z());
    EXPECT_LT((read - p).norm(), 1e-9);
  }
  double extra;
  EXPECT_FALSE(in >> extra);
}

TEST(SlamOutput, WritesFourFilesThatReadBack) {
  const ScratchFolder scratch("slam_output_test");
  const std::filesystem::path& dir = scratch.path();
  Trajectory trajectory;
  trajectory.Add(1.5, Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())),
                             Eigen::Vector3d(1, 2, 3)));
  trajectory.Add(1.6, Rigid3::Identity());
  Trajectory keyframes;
  keyframes.AddFrom(trajectory, 0);
  SlamRunStats stats;
  stats.frames = 10;
  stats.frames_tracked = 8;
  stats.losses = 2;
  stats.markers = true;
  stats.whole_map_marker_adjustments = 2;
  stats.map_merges = 1;
  stats.marker_rejections = 4;
  stats.refined_frame_poses = 17;
  stats.yielded_bundle_adjustments = 9;
  stats.radial_calibrations = 1;
  stats.inconsistent_poses = 5;
  stats.map_rotation_disambiguations = 3;
  TimingSummary summary;
  summary.count = 8;
  summary.median = 12.5;
  stats.timings_ms.emplace_back("tracking", summary);
  WriteSlamOutput(dir, trajectory, keyframes, {{0, 0, 1}}, stats);
  const Trajectory read = ReadTumTrajectory(dir / "trajectory.tum");
  ASSERT_EQ(read.size(), 2u);
  EXPECT_DOUBLE_EQ(read.timestamps[0], 1.5);
  EXPECT_LT((read.poses[0].translation - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
  EXPECT_LT(read.poses[0].rotation.angularDistance(trajectory.poses[0].rotation), 1e-12);
  EXPECT_EQ(ReadTumTrajectory(dir / "keyframes.tum").size(), 1u);
  EXPECT_EQ(ReadRunStats(dir / "stats.json").losses, 2);
  const std::string json = ReadTextFile(dir / "stats.json");
  EXPECT_NE(json.find("\"median\": 12.5"), std::string::npos);
  EXPECT_NE(json.find("\"tracked_fraction\": 0.8"), std::string::npos);
  EXPECT_NE(json.find("\"whole_map_adjustments\": 2"), std::string::npos);
  EXPECT_NE(json.find("\"map_merges\": 1"), std::string::npos);
  EXPECT_NE(json.find("\"rejected_keypoint_poses\": 4"), std::string::npos);
  EXPECT_NE(json.find("\"refined_frame_poses\": 17"), std::string::npos);
  EXPECT_NE(json.find("\"yielded_bundle_adjustments\": 9"), std::string::npos);
  EXPECT_NE(json.find("\"radial_calibrations\": 1"), std::string::npos);
  EXPECT_NE(json.find("\"left_out\": 5"), std::string::npos);
  EXPECT_NE(json.find("\"dropped\": 0"), std::string::npos);
  EXPECT_NE(json.find("\"interrupted\": false"), std::string::npos);
  EXPECT_NE(json.find("\"disambiguated_by_map_rotation\": 3"), std::string::npos);
  EXPECT_NE(ReadTextFile(dir / "map.ply").find("element vertex 1"), std::string::npos);
}

}  // namespace
}  // namespace arucoslam
