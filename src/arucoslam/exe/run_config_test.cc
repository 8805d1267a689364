// `arucoslam run --print-config` and `--config`: the printed defaults are run's own (the run
// they give is the default run, byte for byte, blocking), a changed option changes the run,
// flags override the file, and bad files are one line naming the file, exit status 2, with
// nothing written. On a rendered sequence of 8.5 s (128 frames of 320x240 with markers).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "arucoslam/exe/aisle_sequence_test_util.h"
#include "arucoslam/exe/command_test_util.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;
using testing_util::SplitCommandResult;

class RunConfigTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("arucoslam_run_config_test_" + std::to_string(getpid()));
    SplitCommandResult result = testing_util::MakeAisleTeachSequence(dir_);
    ASSERT_EQ(result.status, 0) << result.err;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static SplitCommandResult Run(const std::string& arguments) {
    return testing_util::RunArucoslamSplit(arguments, dir_);
  }
  // A blocking run of the sequence into dir_/out.
  static SplitCommandResult RunSequence(const std::string& out, const std::string& extra = "") {
    return Run("run --dataset " + (dir_ / "seq_a").string() + " --out " + (dir_ / out).string() +
               " --blocking --quiet " + extra);
  }
  static std::string Read(const std::string& relative) { return ReadTextFile(dir_ / relative); }

  static fs::path dir_;
};

fs::path RunConfigTest::dir_;

TEST_F(RunConfigTest, PrintedDefaultsReproduceTheDefaultRunByteForByte) {
  const SplitCommandResult printed = Run("run --print-config");
  ASSERT_EQ(printed.status, 0) << printed.err;
  EXPECT_EQ(printed.err, "");
  // Run's own values where they differ from the library's (threaded; FAST floor 5).
  EXPECT_NE(printed.out.find("\nblocking: false  # "), std::string::npos);
  EXPECT_NE(printed.out.find("\n  min_fast_threshold: 5  # "), std::string::npos);
  WriteTextFileAtomically(dir_ / "defaults.yaml", printed.out);

  SplitCommandResult result = RunSequence("default");
  ASSERT_EQ(result.status, 0) << result.err;
  result = RunSequence("from_config", "--config " + (dir_ / "defaults.yaml").string());
  ASSERT_EQ(result.status, 0) << result.err;
  // In the marker world, so the marker options are exercised too.
  EXPECT_EQ(Read("default/stats.json").find("\"world_alignments\": 0"), std::string::npos);
  for (const char* file : {"trajectory.tum", "keyframes.tum", "map.ply", "markers.json"}) {
    const std::string expected = Read(std::string("default/") + file);
    EXPECT_GT(expected.size(), 1000u) << file;
    EXPECT_TRUE(Read(std::string("from_config/") + file) == expected) << file << " differs";
  }

  // The file is read: one option changed changes the run.
  WriteTextFileAtomically(dir_ / "fewer.yaml", "extractor:\n  num_features: 700\n");
  result = RunSequence("fewer", "--config " + (dir_ / "fewer.yaml").string());
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(Read("fewer/trajectory.tum"), Read("default/trajectory.tum"));
}

TEST_F(RunConfigTest, FlagsOverrideTheFileAndKeysLeftOutKeepRunDefaults) {
  WriteTextFileAtomically(dir_ / "some.yaml",
                          "blocking: true\nextractor:\n  num_features: 1500\n"
                          "places:\n  loop_closing: true\n");
  SplitCommandResult result = Run("run --config " + (dir_ / "some.yaml").string() +
                                  " --features 700 --no-loop-closing --print-config");
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("\nblocking: true  # "), std::string::npos);
  EXPECT_NE(result.out.find("\n  num_features: 700  # "), std::string::npos);
  EXPECT_NE(result.out.find("\n  loop_closing: false  # "), std::string::npos);
  EXPECT_NE(result.out.find("\n  min_fast_threshold: 5  # "), std::string::npos);
  result =
      Run("run --config " + (dir_ / "some.yaml").string() + " --ground-vehicle --print-config");
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("\n    height_sigma_m: "), std::string::npos);  // the prior is set
}

TEST_F(RunConfigTest, BadConfigFilesAreOneLineAndExitTwo) {
  struct Case {
    std::string name;
    std::string text;
    std::string expected;  // in the error line, after the file name
  };
  const Case cases[] = {
      {"syntax.yaml", "extractor:\n  num_features: [1000\n", "not valid YAML: line 3"},
      {"unknown.yaml", "tracker:\n  min_motion_matchs: 20\n",
       "tracker.min_motion_matchs (line 2): unknown key (did you mean min_motion_matches?)"},
      {"type.yaml", "extractor:\n  num_features: 1000.5\n",
       "extractor.num_features (line 2): expected an integer, found '1000.5'"},
      {"range.yaml", "keyframes:\n  tracked_ratio: 1.5\n",
       "keyframes.tracked_ratio (line 2): 1.5 is out of range"},
      {"absent.yaml", "", "config file does not exist"},
  };
  for (const Case& c : cases) {
    const fs::path file = dir_ / c.name;
    if (!c.text.empty()) WriteTextFileAtomically(file, c.text);
    const SplitCommandResult result = RunSequence("bad_out", "--config " + file.string());
    EXPECT_EQ(result.status, 2) << c.name << "\n" << result.err;
    EXPECT_NE(result.err.find("arucoslam: " + file.string() + ": " + c.expected), std::string::npos)
        << result.err;
    EXPECT_EQ(result.err.find('\n'), result.err.size() - 1) << result.err;
    EXPECT_EQ(result.out, "");
    EXPECT_FALSE(fs::exists(dir_ / "bad_out")) << c.name;
  }
}

}  // namespace
}  // namespace arucoslam
