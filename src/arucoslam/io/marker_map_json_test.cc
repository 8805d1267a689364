#include "arucoslam/io/marker_map_json.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

using Json = nlohmann::json;

// DESIGN.md's example, verbatim.
constexpr const char* kDesignExample = R"({
  "format": "arucoslam.markers/1",
  "dictionary": "DICT_4X4_50",
  "frame": "world",
  "markers": [
    {
      "id": 7,
      "size": 0.30,
      "pose": {"position": {"x": 4.0, "y": 1.5, "z": 0.8},
               "orientation": {"x": 0.5, "y": 0.5, "z": 0.5, "w": 0.5}},
      "corners": [[-0.15, 0.15, 0], [0.15, 0.15, 0], [0.15, -0.15, 0], [-0.15, -0.15, 0]],
      "fixed": true
    }
  ]
})";

// Parses `document` (modified by the caller) and expects an InputError from source
// "test.json" whose message contains every one of `fragments`.
void ExpectRejected(const std::string& text, const std::vector<std::string>& fragments) {
  try {
    ParseMarkerMapJson(text, "test.json");
    ADD_FAILURE() << "accepted: " << text;
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "test.json");
    for (const std::string& fragment : fragments) {
      EXPECT_NE(error.message().find(fragment), std::string::npos)
          << "'" << fragment << "' not in: " << error.message();
    }
  }
}

void ExpectRejected(const std::function<void(Json&)>& edit,
                    const std::vector<std::string>& fragments) {
  Json document = Json::parse(kDesignExample);
  edit(document);
  ExpectRejected(document.dump(), fragments);
}

MarkerMap RandomMap(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.01, 1.0);
  MarkerMap map;
  map.dictionary = "DICT_6X6_250";
  for (int i = 0; i < count; ++i) {
    MarkerInfo marker;
    marker.id = 3 * i + 1;
    marker.size = uniform(rng);
    marker.world_from_marker =
        Rigid3(Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)),
               Eigen::Vector3d(100 * normal(rng), normal(rng), 1e-7 * normal(rng)));
    marker.fixed = (i % 2 == 0);
    map.markers[marker.id] = marker;
  }
  return map;
}

TEST(MarkerMapJsonTest, ReadsTheDesignExample) {
  const MarkerMap map = ParseMarkerMapJson(kDesignExample, "example");
  EXPECT_EQ(map.dictionary, "DICT_4X4_50");
  EXPECT_EQ(map.frame, "world");
  ASSERT_EQ(map.markers.size(), 1u);
  const MarkerInfo* marker = map.Find(7);
  ASSERT_NE(marker, nullptr);
  EXPECT_EQ(marker->size, 0.30);
  EXPECT_TRUE(marker->fixed);
  EXPECT_EQ(marker->world_from_marker.translation, Eigen::Vector3d(4.0, 1.5, 0.8));
  // (0.5, 0.5, 0.5, 0.5) maps marker x to world y, y to z, z to x.
  const Eigen::Matrix3d expected = (Eigen::Matrix3d() << 0, 0, 1, 1, 0, 0, 0, 1, 0).finished();
  EXPECT_LT((marker->world_from_marker.RotationMatrix() - expected).norm(), 1e-15);
}

TEST(MarkerMapJsonTest, RoundTripIsExact) {
  const MarkerMap map = RandomMap(20, 11);
  const std::string text = MarkerMapToJson(map);
  const MarkerMap back = ParseMarkerMapJson(text, "round trip");
  EXPECT_EQ(back.dictionary, map.dictionary);
  EXPECT_EQ(back.frame, map.frame);
  ASSERT_EQ(back.markers.size(), map.markers.size());
  for (const auto& [id, marker] : map.markers) {
    const MarkerInfo* other = back.Find(id);
    ASSERT_NE(other, nullptr) << id;
    EXPECT_EQ(other->size, marker.size);
    EXPECT_EQ(other->fixed, marker.fixed);
    EXPECT_EQ(other->world_from_marker.translation, marker.world_from_marker.translation);
    EXPECT_EQ(other->world_from_marker.rotation.coeffs(),
              marker.world_from_marker.rotation.coeffs());
  }
  EXPECT_EQ(MarkerMapToJson(back), text);
}

TEST(MarkerMapJsonTest, FileRoundTripAndMissingFile) {
  const ScratchFolder scratch("marker_map_json_test");
  const std::filesystem::path& folder = scratch.path();
  const MarkerMap map = RandomMap(3, 5);
  WriteMarkerMapJson(map, folder / "markers.json");
  const MarkerMap back = ReadMarkerMapJson(folder / "markers.json");
  EXPECT_EQ(MarkerMapToJson(back), MarkerMapToJson(map));
  EXPECT_THROW(ReadMarkerMapJson(folder / "absent.json"), InputError);
}

TEST(MarkerMapJsonTest, WriteRefusesAMapThatWouldNotReadBack) {
  MarkerMap map = RandomMap(2, 3);
  map.markers.begin()->second.size = -0.1;
  EXPECT_THROW(MarkerMapToJson(map), InputError);
  map = RandomMap(2, 3);
  map.dictionary = "DICT_NONE";
  EXPECT_THROW(MarkerMapToJson(map), InputError);
}

TEST(MarkerMapJsonTest, RejectsTextThatIsNotJson) {
  ExpectRejected(std::string("{\"format\": "), {"not valid JSON"});
  ExpectRejected(std::string(""), {"not valid JSON"});
  ExpectRejected(std::string("[1, 2]"), {"top level", "expected an object, found an array"});
}

TEST(MarkerMapJsonTest, RejectsUnknownKeysAtEveryLevel) {
  ExpectRejected([](Json& d) { d["units"] = "m"; }, {"top level", "unknown key 'units'"});
  ExpectRejected([](Json& d) { d["markers"][0]["name"] = "dock"; },
                 {"markers[0]", "unknown key 'name'"});
  ExpectRejected([](Json& d) { d["markers"][0]["pose"]["scale"] = 1; },
                 {"markers[0].pose", "unknown key 'scale'"});
  ExpectRejected([](Json& d) { d["markers"][0]["pose"]["position"]["w"] = 1; },
                 {"markers[0].pose.position", "unknown key 'w'"});
  ExpectRejected([](Json& d) { d["markers"][0]["pose"]["orientation"]["v"] = 0; },
                 {"markers[0].pose.orientation", "unknown key 'v'"});
}

TEST(MarkerMapJsonTest, RejectsMissingFields) {
  ExpectRejected([](Json& d) { d.erase("dictionary"); }, {"missing key 'dictionary'"});
  ExpectRejected([](Json& d) { d["markers"][0].erase("size"); },
                 {"markers[0]", "missing key 'size'"});
  ExpectRejected([](Json& d) { d["markers"][0]["pose"]["orientation"].erase("w"); },
                 {"markers[0].pose.orientation", "missing key 'w'"});
  ExpectRejected([](Json& d) { d["markers"][0].erase("corners"); }, {"missing key 'corners'"});
}

TEST(MarkerMapJsonTest, RejectsWrongTypes) {
  ExpectRejected([](Json& d) { d["markers"][0]["id"] = "7"; },
                 {"markers[0].id", "expected an integer, found a string"});
  ExpectRejected([](Json& d) { d["markers"][0]["id"] = 7.5; },
                 {"markers[0].id", "expected an integer, found a number"});
  ExpectRejected([](Json& d) { d["markers"][0]["id"] = -1; }, {"markers[0].id", "non-negative"});
  ExpectRejected([](Json& d) { d["markers"][0]["size"] = "0.3"; },
                 {"markers[0].size", "expected a number, found a string"});
  ExpectRejected([](Json& d) { d["markers"][0]["fixed"] = 1; },
                 {"markers[0].fixed", "expected true or false"});
  ExpectRejected([](Json& d) { d["markers"] = Json::object(); },
                 {"markers", "expected an array, found an object"});
  ExpectRejected([](Json& d) { d["markers"][0]["pose"]["position"]["x"] = nullptr; },
                 {"markers[0].pose.position.x", "expected a number, found null"});
  ExpectRejected(
      [](Json& d) {
        d["markers"][0]["corners"][2] = {0.15, -0.15};
      },
      {"markers[0].corners[2]", "expected 3 numbers"});
  ExpectRejected([](Json& d) { d["dictionary"] = 4; },
                 {"dictionary", "expected a string, found an integer"});
}

TEST(MarkerMapJsonTest, RejectsBadValues) {
  ExpectRejected([](Json& d) { d["format"] = "arucoslam.markers/2"; },
                 {"format", "expected \"arucoslam.markers/1\""});
  ExpectRejected([](Json& d) { d["dictionary"] = "DICT_4X4_51"; },
                 {"dictionary", "unknown marker dictionary \"DICT_4X4_51\"", "DICT_6X6_250"});
  ExpectRejected([](Json& d) { d["markers"][0]["size"] = -0.3; }, {"markers[0].size", "positive"});
  ExpectRejected([](Json& d) { d["markers"][0]["size"] = 0; }, {"markers[0].size", "positive"});
  ExpectRejected([](Json& d) { d["markers"][0]["id"] = 50; },
                 {"markers[0].id", "outside the dictionary (0..49)"});
  ExpectRejected([](Json& d) { d["frame"] = ""; }, {"frame"});
}

TEST(MarkerMapJsonTest, RejectsDuplicateIds) {
  ExpectRejected(
      [](Json& d) {
        d["markers"].push_back(d["markers"][0]);
        d["markers"][1]["pose"]["position"]["x"] = 9.0;
      },
      {"markers[1].id", "duplicate id 7", "markers[0]"});
}

TEST(MarkerMapJsonTest, CornersMustAgreeWithSizeWithin1e6) {
  // 0.5e-6 off: accepted.
  Json document = Json::parse(kDesignExample);
  document["markers"][0]["corners"][1][0] = 0.15 + 0.5e-6;
  EXPECT_NO_THROW(ParseMarkerMapJson(document.dump(), "test.json"));
  ExpectRejected([](Json& d) { d["markers"][0]["corners"][1][0] = 0.15 + 2e-6; },
                 {"markers[0].corners[1]", "top-right", "0.150000, 0.150000, 0.000000"});
  // Corners in the wrong order (clockwise from bottom-left) are rejected too.
  ExpectRejected(
      [](Json& d) {
        d["markers"][0]["corners"] =
            Json::parse("[[-0.15, -0.15, 0], [0.15, -0.15, 0], [0.15, 0.15, 0], [-0.15, 0.15, 0]]");
      },
      {"markers[0].corners[0]", "top-left"});
  ExpectRejected([](Json& d) { d["markers"][0]["corners"].erase(3); },
                 {"markers[0].corners", "expected 4 corners"});
  ExpectRejected([](Json& d) { d["markers"][0]["size"] = 0.31; },
                 {"markers[0].corners[0]", "size 0.310000"});
}

TEST(MarkerMapJsonTest, QuaternionMustBeUnitWithin1e6) {
  // w + 1e-6 gives norm 1 + 0.5e-6: accepted and normalised.
  Json document = Json::parse(kDesignExample);
  document["markers"][0]["pose"]["orientation"]["w"] = 0.5 + 1e-6;
  const MarkerMap map = ParseMarkerMapJson(document.dump(), "test.json");
  EXPECT_NEAR(map.Find(7)->world_from_marker.rotation.norm(), 1.0, 1e-15);
  ExpectRejected(
      [](Json& d) { d["markers"][0]["pose"]["orientation"]["w"] = 0.5 + 4e-6; },  // norm 1 + 2e-6
      {"markers[0].pose.orientation", "quaternion norm 1.000002 is not 1"});
  ExpectRejected(
      [](Json& d) {
        d["markers"][0]["pose"]["orientation"] = {{"x", 0}, {"y", 0}, {"z", 0}, {"w", 0}};
      },
      {"markers[0].pose.orientation", "quaternion norm 0.000000"});
}

}  // namespace
}  // namespace arucoslam
