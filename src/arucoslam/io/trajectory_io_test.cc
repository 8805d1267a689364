#include "arucoslam/io/trajectory_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

const fs::path kEvoData = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "evo_testdata";

// Runs `parse` and returns the InputError's full text ("" when nothing was thrown).
template <typename Fn>
std::string ErrorOf(Fn&& parse) {
  try {
    parse();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(TrajectoryIo, ParsesTumWithCommentsAndXyzwOrder) {
  const std::string text =
      "# timestamp tx ty tz qx qy qz qw\n"
      "\n"
      "1.5 1 2 3 0 0 0.70710678118654752 0.70710678118654752\n"
      "2.0\t4\t5\t6\t0\t0\t0\t1\n";
  const Trajectory trajectory = ParseTumTrajectory(text, "a.txt");
  ASSERT_EQ(trajectory.size(), 2u);
  EXPECT_DOUBLE_EQ(trajectory.timestamps[0], 1.5);
  EXPECT_EQ(trajectory.poses[0].translation, Eigen::Vector3d(1, 2, 3));
  // 90 degrees about z: x axis goes to y.
  const Eigen::Vector3d x_rotated = trajectory.poses[0].rotation * Eigen::Vector3d::UnitX();
  EXPECT_NEAR((x_rotated - Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(trajectory.poses[1].translation.z(), 6.0);
}

TEST(TrajectoryIo, TumRoundTripIsExact) {
  Trajectory trajectory;
  trajectory.Add(1403715524.907143168,
                 Rigid3(Eigen::Quaterniond(0.161996, 0.789985, -0.205376, 0.554528),
                        Eigen::Vector3d(0.1 / 3.0, -2.0 / 7.0, 1e-9)));
  trajectory.Add(1403715525.0, Rigid3(Eigen::Quaterniond(1, 0, 0, 0), Eigen::Vector3d(1, 2, 3)));
  const Trajectory back = ParseTumTrajectory(FormatTumTrajectory(trajectory), "round trip");
  ASSERT_EQ(back.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back.timestamps[i], trajectory.timestamps[i]);
    EXPECT_EQ(back.poses[i].translation, trajectory.poses[i].translation);
    EXPECT_EQ(back.poses[i].rotation.coeffs(), trajectory.poses[i].rotation.coeffs());
  }
}

TEST(TrajectoryIo, EurocQuaternionIsWFirstAndNanosecondsBecomeSeconds) {
  const std::string text =
      "#timestamp, p_x, p_y, p_z, q_w, q_x, q_y, q_z, v_x\n"
      "1403715524907143168,0.5,2.0,0.9,0.70710678118654752,0,0,0.70710678118654752,7\n";
  const Trajectory trajectory = ParseEurocTrajectory(text, "gt.csv");
  ASSERT_EQ(trajectory.size(), 1u);
  EXPECT_DOUBLE_EQ(trajectory.timestamps[0], 1403715524.907143168);
  EXPECT_NEAR(trajectory.poses[0].rotation.w(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(trajectory.poses[0].rotation.z(), std::sqrt(0.5), 1e-15);
  EXPECT_DOUBLE_EQ(trajectory.poses[0].translation.y(), 2.0);
}

TEST(TrajectoryIo, KittiUsesTimesFileOrIndex) {
  const std::string text =
      "1 0 0 1 0 1 0 2 0 0 1 3\n"
      "0 -1 0 4 1 0 0 5 0 0 1 6\n";
  const Trajectory by_index = ParseKittiTrajectory(text, "poses.txt");
  ASSERT_EQ(by_index.size(), 2u);
  EXPECT_EQ(by_index.timestamps[1], 1.0);
  EXPECT_EQ(by_index.poses[1].translation, Eigen::Vector3d(4, 5, 6));
  EXPECT_NEAR(
      (by_index.poses[1].rotation * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(),
      0.0, 1e-15);
  const Trajectory timed = ParseKittiTrajectory(text, "poses.txt", "0.0\n0.25\n", "times.txt");
  EXPECT_EQ(timed.timestamps[1], 0.25);
  EXPECT_NE(ErrorOf([&] {
              ParseKittiTrajectory(text, "poses.txt", "0.0\n", "times.txt");
            }).find("times.txt: 1 timestamps for 2 poses"),
            std::string::npos);
}

TEST(TrajectoryIo, MalformedLineNamesFileAndLine) {
  const std::string short_line = "# c\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n";
  EXPECT_EQ(ErrorOf([&] { ParseTumTrajectory(short_line, "est.txt"); }),
            "est.txt: line 3: expected 8 numbers (TUM: t tx ty tz qx qy qz qw), found 7");
  const std::string word = "1 0 0 0 0 0 0 1\n2 0 0 abc 0 0 0 1\n";
  EXPECT_EQ(ErrorOf([&] { ParseTumTrajectory(word, "est.txt"); }),
            "est.txt: line 2: 'abc' is not a number");
  const std::string nan = "1 0 0 0 0 0 0 1\n2 0 nan 0 0 0 0 1\n";
  EXPECT_EQ(ErrorOf([&] { ParseTumTrajectory(nan, "est.txt"); }),
            "est.txt: line 2: value 'nan' is not finite");
  const std::string backwards = "2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n";
  EXPECT_NE(
      ErrorOf([&] { ParseTumTrajectory(backwards, "est.txt"); }).find("est.txt: line 2: timestamp"),
      std::string::npos);
  const std::string zero_quaternion = "1 0 0 0 0 0 0 0\n";
  EXPECT_NE(ErrorOf([&] {
              ParseTumTrajectory(zero_quaternion, "est.txt");
            }).find("line 1: quaternion norm"),
            std::string::npos);
  EXPECT_EQ(ErrorOf([&] { ParseTumTrajectory("# nothing\n", "est.txt"); }),
            "est.txt: no poses in the file");
  EXPECT_EQ(ErrorOf([&] { ParseEurocTrajectory("#h\n1,2,3\n", "gt.csv"); }),
            "gt.csv: line 2: expected at least 8 numbers (EuRoC: t[ns] px py pz qw qx qy qz "
            "...), found 3");
  EXPECT_NE(ErrorOf([&] {
              ParseKittiTrajectory("1 0 0 0 0 1 0 0 0 0 1\n", "k.txt");
            }).find("k.txt: line 1: expected 12 numbers"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              ParseKittiTrajectory("2 0 0 0 0 1 0 0 0 0 1 0\n", "k.txt");
            }).find("determinant 2"),
            std::string::npos);
}

TEST(TrajectoryIo, DetectsFormats) {
  EXPECT_EQ(DetectTrajectoryFormat("# x\n1 0 0 0 0 0 0 1\n"), TrajectoryFormat::kTum);
  EXPECT_EQ(DetectTrajectoryFormat("#h\n1403715524907143168,1,2,3,1,0,0,0\n"),
            TrajectoryFormat::kEuroc);
  EXPECT_EQ(DetectTrajectoryFormat("1 0 0 0 0 1 0 0 0 0 1 0\n"), TrajectoryFormat::kKitti);
}

TEST(TrajectoryIo, RunStatsSchema) {
  const RunTrackingStats stats =
      ParseRunStats(R"({"tracking": {"losses": 3, "relocalisations": 2}, "other": 1})", "s");
  EXPECT_EQ(stats.losses, 3);
  EXPECT_EQ(stats.relocalisations, 2);
  EXPECT_EQ(ErrorOf([] {
              ParseRunStats(R"({"tracking": {"losses": -1, "relocalisations": 0}})", "stats.json");
            }),
            "stats.json: tracking.losses: expected an integer >= 0");
  EXPECT_EQ(ErrorOf([] { ParseRunStats(R"({"tracking": {"losses": 1}})", "stats.json"); }),
            "stats.json: tracking.relocalisations: missing");
  EXPECT_NE(ErrorOf([] { ParseRunStats("{", "stats.json"); }).find("not valid JSON"),
            std::string::npos);
}

TEST(TrajectoryIo, ReadsEvoTestData) {
  if (!fs::is_directory(kEvoData)) GTEST_SKIP() << "missing test data folder " << kEvoData;
  const Trajectory euroc = ReadTrajectory(kEvoData / "V102_groundtruth.csv");
  EXPECT_EQ(euroc.size(), 16702u);
  EXPECT_DOUBLE_EQ(euroc.poses[0].translation.x(), 0.515356);
  EXPECT_NEAR(euroc.poses[0].rotation.w(), 0.161996, 1e-6);
  const Trajectory kitti = ReadTrajectory(kEvoData / "KITTI_00_gt.txt");  // + _times.txt
  EXPECT_EQ(kitti.size(), 4541u);
  EXPECT_DOUBLE_EQ(kitti.timestamps[1], 1.037359e-01);
  EXPECT_DOUBLE_EQ(kitti.poses[2].translation.z(), 1.716275);
  const Trajectory tum = ReadTrajectory(kEvoData / "fr2_desk_groundtruth.txt");
  EXPECT_EQ(tum.size(), 20957u);
}

TEST(TrajectoryIo, WriteIsAtomicAndReadable) {
  const ScratchFolder scratch("trajectory_io_test");
  const fs::path& dir = scratch.path();
  Trajectory trajectory;
  trajectory.Add(0.0, Rigid3());
  trajectory.Add(0.1, Rigid3(Eigen::Quaterniond(0, 1, 0, 0), Eigen::Vector3d(1, 0, 0)));
  WriteTumTrajectory(dir / "t.txt", trajectory);
  const Trajectory back = ReadTrajectory(dir / "t.txt");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back.poses[1].rotation.x(), 1.0);
  EXPECT_NE(ErrorOf([&] { ReadTrajectory(dir / "missing.txt"); }).find("missing.txt"),
            std::string::npos);
}

}  // namespace
}  // namespace arucoslam
