// Runs the `arucoslam` binary: `world factory` then `simulate`, and its bad-input errors.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string err;
};

class SimulateCommandTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("arucoslam_simulate_test_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const Result factory = Run("world factory --seed 3 --aisles 1 --aisle-length 8 --wall-markers 0 --out " +
                               (dir_ / "factory").string());
    ASSERT_EQ(factory.status, 0) << factory.err;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static Result Run(const std::string& arguments) {
    const fs::path err_file = dir_ / "stderr.txt";
    const std::string command = std::string(ARUCOSLAM_BINARY) + " " + arguments + " > " +
                                (dir_ / "stdout.txt").string() + " 2> " + err_file.string();
    const int raw = std::system(command.c_str());
    Result result;
    result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    std::ifstream in(err_file);
    std::stringstream text;
    text << in.rdbuf();
    result.err = text.str();
    return result;
  }

  static std::string Simulate(const std::string& out, const std::string& extra = "") {
    return "simulate --world " + (dir_ / "factory" / "world.sdf").string() + " --path " +
           (dir_ / "factory" / "path.json").string() + " --out " + (dir_ / out).string() +
           " --max-seconds 0.2 --quiet " + extra;
  }

  static std::string ReadBytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }

  static fs::path dir_;
};

fs::path SimulateCommandTest::dir_;

TEST_F(SimulateCommandTest, WritesSequenceAndRepeatsItExactly) {
  const Result first = Run(Simulate("seq_a"));
  ASSERT_EQ(first.status, 0) << first.err;
  const Result second = Run(Simulate("seq_b"));
  ASSERT_EQ(second.status, 0) << second.err;
  const fs::path seq = dir_ / "seq_a";
  for (const char* file : {"world.sdf", "markers.json", "mav0/cam0/data.csv",
                           "mav0/cam0/sensor.yaml", "mav0/state_groundtruth_estimate0/data.csv"}) {
    EXPECT_TRUE(fs::is_regular_file(seq / file)) << file;
  }
  int images = 0;
  for (const auto& entry : fs::directory_iterator(seq / "mav0" / "cam0" / "data")) {
    ++images;
    EXPECT_EQ(ReadBytes(entry.path()),
              ReadBytes(dir_ / "seq_b" / "mav0" / "cam0" / "data" / entry.path().filename()))
        << entry.path();
  }
  EXPECT_EQ(images, 7);  // t = 0 .. 0.2 s at 30 Hz
}

TEST_F(SimulateCommandTest, BadInputIsOneLineAndStatusTwo) {
  const std::string world = (dir_ / "factory" / "world.sdf").string();
  const std::string path = (dir_ / "factory" / "path.json").string();
  std::ofstream(dir_ / "broken.json") << "{\"format\": \"arucoslam.path/1\", \"waypoints\": [";
  std::ofstream(dir_ / "broken.sdf") << "<sdf version='1.9'><world name='w'>";
  const std::string cases[] = {
      "simulate --world " + (dir_ / "absent.sdf").string() + " --path " + path + " --out " +
          (dir_ / "x").string(),
      "simulate --world " + (dir_ / "broken.sdf").string() + " --path " + path + " --out " +
          (dir_ / "x").string(),
      "simulate --world " + world + " --path " + (dir_ / "broken.json").string() + " --out " +
          (dir_ / "x").string(),
      Simulate("x", "--run sideways"),
      Simulate("x", "--noise -1"),
  };
  for (const std::string& arguments : cases) {
    const Result result = Run(arguments);
    EXPECT_EQ(result.status, 2) << arguments << "\n" << result.err;
    EXPECT_EQ(result.err.rfind("arucoslam: ", 0), 0u) << result.err;
    EXPECT_EQ(result.err.find('\n'), result.err.size() - 1) << result.err;
    EXPECT_FALSE(fs::exists(dir_ / "x")) << arguments;
  }
}

}  // namespace
