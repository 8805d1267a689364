// Runs the `arucoslam eval` binary: evo's numbers on its test data, the files it writes,
// and one clear line with exit status 2 for each kind of bad input.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "arucoslam/exe/command_test_util.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

const fs::path kEvoData = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "evo_testdata";

using RunResult = testing_util::SplitCommandResult;

class EvalCommandTest : public ::testing::Test {
 protected:
  RunResult Run(const std::string& arguments) const {
    return testing_util::RunArucoslamSplit("eval " + arguments, folder_);
  }

  // A small TUM ground truth: 50 poses at 10 Hz from t = 100 s.
  fs::path WriteGroundTruth() const {
    std::string text = "# t tx ty tz qx qy qz qw\n";
    for (int i = 0; i < 50; ++i) {
      text += std::to_string(100.0 + 0.1 * i) + " " + std::to_string(0.1 * i) + " 0 0 0 0 0 1\n";
    }
    const fs::path path = folder_ / "gt.txt";
    WriteTextFileAtomically(path, text);
    return path;
  }

  fs::path Write(const std::string& name, const std::string& text) const {
    WriteTextFileAtomically(folder_ / name, text);
    return folder_ / name;
  }

  ScratchFolder scratch_{"eval_command_test"};
  const fs::path& folder_ = scratch_.path();
};

TEST_F(EvalCommandTest, ReproducesEvoAndWritesResultsAndPlots) {
  if (!fs::is_directory(kEvoData)) GTEST_SKIP() << "missing test data folder " << kEvoData;
  const fs::path out = folder_ / "out";
  const RunResult run =
      Run("--gt " + (kEvoData / "fr2_desk_groundtruth.txt").string() + " --est " +
          (kEvoData / "fr2_desk_ORB_kf_mono.txt").string() + " --est " +
          (kEvoData / "fr2_desk_ORB.txt").string() + " --label mono --label full --align sim3" +
          " --rpe 1frames --rpe 0.5m --at 10 --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("mono"), std::string::npos);
  EXPECT_NE(run.out.find("APE translation rmse [m]"), std::string::npos);
  const nlohmann::json json = nlohmann::json::parse(ReadTextFile(out / "results.json"));
  ASSERT_EQ(json["estimates"].size(), 2u);
  // evo v1.36.5: fr2_desk_ORB_kf_mono, APE Sim3, 118 pairs, rmse 0.007729 (README of the data).
  const nlohmann::json& mono = json["estimates"][0];
  EXPECT_EQ(mono["poses"]["pairs"], 118);
  EXPECT_NEAR(mono["ape"]["translation_m"]["rmse"].get<double>(), 0.007729, 5e-7);
  EXPECT_NEAR(mono["rpe"][0]["translation_m"]["rmse"].get<double>(), 0.007069, 5e-7);
  EXPECT_EQ(mono["rpe"][0]["translation_m"]["count"], 117);
  EXPECT_EQ(json["estimates"][1]["poses"]["pairs"], 2174);
  for (const char* name :
       {"trajectory_top_down.svg", "ape_over_time.svg", "per_axis_error.svg", "table.txt"}) {
    EXPECT_TRUE(fs::is_regular_file(out / name)) << name;
  }
  EXPECT_NE(ReadTextFile(out / "trajectory_top_down.svg").find(">full</text>"), std::string::npos);
}

TEST_F(EvalCommandTest, StatsFileIsReported) {
  const fs::path gt = WriteGroundTruth();
  const fs::path stats =
      Write("stats.json", R"({"tracking": {"losses": 2, "relocalisations": 1}})");
  const RunResult run = Run("--gt " + gt.string() + " --est " + gt.string() + " --stats " +
                            stats.string() + " --out " + (folder_ / "o").string());
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("2 / 1"), std::string::npos);
  const nlohmann::json json = nlohmann::json::parse(ReadTextFile(folder_ / "o" / "results.json"));
  EXPECT_EQ(json["estimates"][0]["tracking"]["relocalisations"], 1);
  EXPECT_EQ(json["estimates"][0]["ape"]["translation_m"]["rmse"].get<double>(), 0.0);
}

// A ground truth driving 1 m/s along x for 10 s and an estimate whose steps shrink by 2% a
// second: windows of 2.5 s see it 2.5% smaller, then 7.5%, 12.5% and 17.5%.
TEST_F(EvalCommandTest, ScaleDriftOverWindows) {
  std::string gt_text, est_text;
  double x = 0.0;
  for (int i = 0; i < 100; ++i) {
    const double t = i / 10.0;
    gt_text += fmt::format("{:.2f} {:.6f} 0 0 0 0 0 1\n", 100.0 + t, 0.1 * i);
    est_text += fmt::format("{:.2f} {:.6f} 0 0 0 0 0 1\n", 100.0 + t, x);
    x += 0.1 * (1.0 - 0.02 * t);
  }
  const fs::path gt = Write("gt.txt", gt_text);
  const fs::path est = Write("est.txt", est_text);
  const RunResult run = Run("--gt " + gt.string() + " --est " + est.string() +
                            " --scale-window 2.5 --out " + (folder_ / "o").string());
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("scale drift: last / first window - 1"), std::string::npos) << run.out;
  const nlohmann::json json = nlohmann::json::parse(ReadTextFile(folder_ / "o" / "results.json"));
  const nlohmann::json& drift = json["estimates"][0]["scale_drift"];
  ASSERT_EQ(drift["windows"].size(), 4u);
  EXPECT_NEAR(drift["windows"][0]["estimate_per_truth"].get<double>(), 1.0 - 0.02 * 1.2, 2e-3);
  EXPECT_NEAR(drift["windows"][3]["estimate_per_truth"].get<double>(), 1.0 - 0.02 * 8.7, 2e-3);
  EXPECT_NEAR(drift["last_over_first"].get<double>(), (1.0 - 0.02 * 8.7) / (1.0 - 0.02 * 1.2) - 1.0,
              3e-3);
  const RunResult bad =
      Run("--gt " + gt.string() + " --est " + est.string() + " --scale-window -1");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--scale-window: expected seconds >= 0"), std::string::npos) << bad.err;
}

TEST_F(EvalCommandTest, MapAccuracyAgainstAnSdfWorld) {
  const fs::path gt = WriteGroundTruth();
  // A 2 m cube standing on z = 0 at x = 10; map points 1, 2 and 3 cm and 1 m from its faces.
  const fs::path world = Write("world.sdf", R"(<?xml version="1.0"?>
<sdf version="1.9">
  <world name="w">
    <model name="cube">
      <static>true</static>
      <pose>10 0 1 0 0 0</pose>
      <link name="link">
        <visual name="v"><geometry><box><size>2 2 2</size></box></geometry></visual>
      </link>
    </model>
  </world>
</sdf>
)");
  const fs::path map = Write("map.ply",
                             "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                             "property float y\nproperty float z\nend_header\n"
                             "8.99 0 1\n10 1.02 1\n10 0 2.03\n12 0 1\n");
  const fs::path out = folder_ / "o";
  const RunResult run = Run("--gt " + gt.string() + " --est " + gt.string() + " --map " +
                            map.string() + " --world " + world.string() + " --out " +
                            out.string());
  ASSERT_EQ(run.status, 0) << run.err;
  const nlohmann::json json = nlohmann::json::parse(ReadTextFile(out / "results.json"));
  const nlohmann::json& accuracy = json["estimates"][0]["map"];
  EXPECT_EQ(accuracy["points"], 4);
  EXPECT_NEAR(accuracy["median_m"].get<double>(), 0.025, 1e-6);
  EXPECT_NEAR(accuracy["fraction_within"].get<double>(), 0.75, 1e-12);
  const RunResult no_world =
      Run("--gt " + gt.string() + " --est " + gt.string() + " --map " + map.string());
  EXPECT_EQ(no_world.status, 2);
  EXPECT_NE(no_world.err.find("--map: map accuracy needs the true world"), std::string::npos);
}

TEST_F(EvalCommandTest, BadInputIsOneLineAndStatusTwo) {
  const fs::path gt = WriteGroundTruth();
  const fs::path out = folder_ / "not_written";
  struct Case {
    std::string est_text;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"100.0 0 0 0 0 0 0 1\n100.1 0 0 0 0 0 1\n", "line 2: expected 8 numbers"},
      {"100.0 0 0 0 0 0 0 1\n100.1 0 nan 0 0 0 0 1\n", "line 2: value 'nan' is not finite"},
      {"900 0 0 0 0 0 0 1\n901 0 0 0 0 0 0 1\n902 0 0 0 0 0 0 1\n",
       "no pose within 0.01 s of a ground-truth pose"},
      {"100.0 0 0 0 0 0 0 1\n100.1 0.1 0 0 0 0 0 1\n", "only 2 pose(s) associated"},
  };
  for (const Case& c : cases) {
    const fs::path est = Write("est.txt", c.est_text);
    const RunResult run =
        Run("--gt " + gt.string() + " --est " + est.string() + " --out " + out.string());
    EXPECT_EQ(run.status, 2) << c.expected;
    EXPECT_NE(run.err.find("arucoslam: " + est.string() + ": "), std::string::npos) << run.err;
    EXPECT_NE(run.err.find(c.expected), std::string::npos) << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_FALSE(fs::exists(out)) << "nothing is written on bad input";
  }
  const RunResult bad_align =
      Run("--gt " + gt.string() + " --est " + gt.string() + " --align affine");
  EXPECT_EQ(bad_align.status, 2);
  EXPECT_NE(bad_align.err.find("--align: expected none, se3 or sim3"), std::string::npos);
  const RunResult bad_rpe = Run("--gt " + gt.string() + " --est " + gt.string() + " --rpe 3x");
  EXPECT_EQ(bad_rpe.status, 2);
  EXPECT_NE(bad_rpe.err.find("--rpe: cannot read '3x'"), std::string::npos);
  const RunResult missing =
      Run("--gt " + (folder_ / "nope.txt").string() + " --est " + gt.string());
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("nope.txt"), std::string::npos);
}

}  // namespace
}  // namespace arucoslam
