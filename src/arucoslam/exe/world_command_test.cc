#include <gtest/gtest.h>

#include "arucoslam/exe/command_test_util.h"
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/io/path_json.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

using testing_util::RunArucoslam;

class WorldCommandTest : public ::testing::Test {
 protected:
  ScratchFolder scratch_{"world_command_test"};
  const fs::path& dir_ = scratch_.path();
};

TEST_F(WorldCommandTest, WritesTheFactoryFolder) {
  const fs::path out = dir_ / "factory";
  const auto result = RunArucoslam(
      "world factory --seed 3 --aisles 2 --aisle-length 12 --texture low --wall-markers 0 "
      "--markers-per-dock 2 --marker-size 0.25 --out " +
      out.string());
  ASSERT_EQ(result.status, 0) << result.output;
  EXPECT_NE(result.output.find("12 markers at 6 docks"), std::string::npos) << result.output;
  for (const char* file : {"world.sdf", "markers.json", "path.json", "textures/floor_0.png",
                           "textures/wall_0.png", "markers/0.png", "markers/11.png"}) {
    EXPECT_TRUE(fs::is_regular_file(out / file)) << file;
  }
  const MarkerMap markers = ReadMarkerMapJson(out / "markers.json");
  ASSERT_EQ(markers.markers.size(), 12u);
  EXPECT_EQ(markers.markers.begin()->second.size, 0.25);
  const PathSpec path = ReadPathJson(out / "path.json");
  EXPECT_EQ(path.options.seed, 3u);
  EXPECT_GE(path.waypoints.size(), 5u);
  EXPECT_EQ(path.waypoints.front().x, path.waypoints.back().x);  // a loop
  EXPECT_EQ(path.waypoints.front().y, path.waypoints.back().y);
}

TEST_F(WorldCommandTest, MarkersOffWritesAnEmptyMap) {
  const fs::path out = dir_ / "bare";
  const auto result = RunArucoslam(
      "world factory --seed 1 --aisles 1 --aisle-length 8 --markers off --out " + out.string());
  ASSERT_EQ(result.status, 0) << result.output;
  EXPECT_TRUE(ReadMarkerMapJson(out / "markers.json").markers.empty());
  EXPECT_FALSE(fs::exists(out / "markers" / "0.png"));
}

TEST_F(WorldCommandTest, WallMarkersAreCountedApartFromTheDocks) {
  const fs::path out = dir_ / "wall";
  const auto result = RunArucoslam(
      "world factory --seed 1 --aisles 1 --aisle-length 8 --wall-markers 3 --out " + out.string());
  ASSERT_EQ(result.status, 0) << result.output;
  EXPECT_NE(result.output.find("4 markers at 4 docks and "), std::string::npos) << result.output;
  const MarkerMap markers = ReadMarkerMapJson(out / "markers.json");
  EXPECT_GT(markers.markers.size(), 4u);
  EXPECT_NE(
      result.output.find(std::to_string(markers.markers.size() - 4) + " on the corridor wall"),
      std::string::npos)
      << result.output;
}

TEST_F(WorldCommandTest, BadInputIsOneLineAndWritesNothing) {
  const fs::path out = dir_ / "never";
  for (const std::string& arguments :
       {std::string("--texture shiny"), std::string("--markers maybe"), std::string("--aisles 0"),
        std::string("--aisle-length 100"), std::string("--dictionary DICT_9X9_1"),
        std::string("--aisles 8 --markers-per-dock 4"), std::string("--camera-height 1.5"),
        std::string("--wall-markers 0.5"), std::string("--wall-markers 1 --markers-per-dock 3")}) {
    const auto result =
        RunArucoslam("world factory --seed 1 " + arguments + " --out " + out.string());
    EXPECT_EQ(result.status, 2) << arguments << ": " << result.output;
    EXPECT_EQ(result.output.rfind("arucoslam: ", 0), 0u) << result.output;
    EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
    EXPECT_FALSE(fs::exists(out)) << arguments;
  }
  EXPECT_EQ(RunArucoslam("world factory --seed 1").status, 2);  // --out is required
}

}  // namespace
}  // namespace arucoslam
