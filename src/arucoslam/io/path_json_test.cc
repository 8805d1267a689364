#include "arucoslam/io/path_json.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

const char* kValid = R"({
  "format": "arucoslam.path/1", "frame": "world",
  "waypoints": [{"x": 0, "y": 0}, {"x": 10.5, "y": 0, "turn_radius_m": 0.8}, {"x": 10.5, "y": 4}],
  "options": {"camera_height_m": 0.45, "seed": 7}
})";

// The message of the InputError that parsing `text` throws ("" when none).
std::string ErrorOf(const std::string& text) {
  try {
    ParsePathJson(text, "path.json");
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "path.json");
    return error.message();
  }
  return "";
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(PathJsonTest, ReadsWaypointsAndKeepsDefaults) {
  const PathSpec spec = ParsePathJson(kValid, "path.json");
  ASSERT_EQ(spec.waypoints.size(), 3u);
  EXPECT_EQ(spec.waypoints[1].x, 10.5);
  EXPECT_EQ(spec.waypoints[1].turn_radius_m, 0.8);
  EXPECT_EQ(spec.waypoints[2].turn_radius_m, 0.0);
  EXPECT_EQ(spec.options.camera_height_m, 0.45);
  EXPECT_EQ(spec.options.seed, 7u);
  EXPECT_EQ(spec.options.max_speed_m_s, PathOptions().max_speed_m_s);
}

TEST(PathJsonTest, RoundTripIsExact) {
  PathSpec spec;
  spec.waypoints = {{0.1, -2.0 / 3.0}, {1e-3 + 7.0, 3.14159265358979, 0.77}, {7.3, 9.9}};
  spec.options.camera_height_m = 0.9123456789012345;
  spec.options.repeat_deviation_m = 0.1 / 3.0;
  spec.options.seed = 4000000000u;
  const auto file = std::filesystem::temp_directory_path() / "arucoslam_path_json_test.json";
  WritePathJson(file, spec);
  const PathSpec back = ReadPathJson(file);
  std::filesystem::remove(file);
  ASSERT_EQ(back.waypoints.size(), spec.waypoints.size());
  for (std::size_t i = 0; i < spec.waypoints.size(); ++i) {
    EXPECT_EQ(back.waypoints[i].x, spec.waypoints[i].x);
    EXPECT_EQ(back.waypoints[i].y, spec.waypoints[i].y);
    EXPECT_EQ(back.waypoints[i].turn_radius_m, spec.waypoints[i].turn_radius_m);
  }
  EXPECT_EQ(PathJsonText(back), PathJsonText(spec));
  EXPECT_EQ(back.options.camera_height_m, spec.options.camera_height_m);
  EXPECT_EQ(back.options.repeat_deviation_m, spec.options.repeat_deviation_m);
  EXPECT_EQ(back.options.seed, spec.options.seed);
}

TEST(PathJsonTest, MalformedFilesAreClearErrors) {
  const std::string valid = kValid;
  EXPECT_EQ(ErrorOf(valid), "");
  EXPECT_NE(ErrorOf("{\"format\": ").find("not valid JSON"), std::string::npos);
  EXPECT_NE(ErrorOf("[1, 2]").find("JSON object"), std::string::npos);
  EXPECT_NE(ErrorOf(Replace(valid, "arucoslam.path/1", "other/2")).find("format"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(valid, "\"world\"", "\"map\"")).find("frame"), std::string::npos);
  EXPECT_EQ(ErrorOf(Replace(valid, "\"frame\"", "\"colour\"")), "unknown key 'colour'");
  EXPECT_EQ(ErrorOf(Replace(valid, "\"x\": 10.5", "\"x\": \"10.5\"")),
            "waypoints[1].x: expected a number, found \"10.5\"");
  EXPECT_EQ(ErrorOf(Replace(valid, "{\"x\": 0, \"y\": 0}", "{\"y\": 0}")),
            "waypoints[0]: missing \"x\"");
  EXPECT_EQ(ErrorOf(Replace(valid, "{\"x\": 0, \"y\": 0}", "[0, 0]")).substr(0, 25),
            "waypoints[0]: expected an");
  EXPECT_EQ(ErrorOf(Replace(valid, "\"turn_radius_m\"", "\"radius\"")),
            "waypoints[1]: unknown key 'radius'");
  EXPECT_EQ(ErrorOf(Replace(valid, "0.45", "1.5")),
            "options.camera_height_m: 1.5 is outside [0.3, 1.0]");
  EXPECT_EQ(ErrorOf(Replace(valid, "\"camera_height_m\"", "\"height\"")),
            "options: unknown key 'height'");
  EXPECT_NE(ErrorOf(Replace(valid, "\"seed\": 7", "\"seed\": -1")).find("options.seed"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(valid, "\"seed\": 7", "\"seed\": 1.5")).find("options.seed"),
            std::string::npos);
  EXPECT_NE(ErrorOf(R"({"format": "arucoslam.path/1", "waypoints": 3})")
                .find("waypoints: expected an array"),
            std::string::npos);
  // Drivable-route checks: a reversal in one corner, waypoints on top of each other.
  EXPECT_NE(ErrorOf(Replace(valid, "{\"x\": 10.5, \"y\": 4}", "{\"x\": 0.5, \"y\": 0.01}"))
                .find("waypoints[1]: the route turns back"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Replace(valid, "{\"x\": 10.5, \"y\": 4}", "{\"x\": 10.51, \"y\": 0}"))
                .find("waypoints[2]: closer"),
            std::string::npos);
}

TEST(PathJsonTest, MissingFileNamesIt) {
  try {
    ReadPathJson("/nonexistent/route.json");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent/route.json"), std::string::npos);
  }
}

}  // namespace
}  // namespace arucoslam
