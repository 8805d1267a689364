#include "arucoslam/io/marker_map_json.h"

#include <cmath>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>

#include "arucoslam/markers/dictionary.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

using Json = nlohmann::json;

std::string TypeName(const Json& value) {
  if (value.is_number_integer()) return "an integer";
  if (value.is_number()) return "a number";
  if (value.is_string()) return "a string";
  if (value.is_boolean()) return "a boolean";
  if (value.is_array()) return "an array";
  if (value.is_object()) return "an object";
  return "null";
}

// Checks of one JSON value found at `field` (e.g. "markers[2].pose") of file `source`.
class Field {
 public:
  Field(const Json& value, std::string field, const std::string& source)
      : value_(value), field_(std::move(field)), source_(source) {}

  [[noreturn]] void Fail(const std::string& what) const {
    throw InputError(source_, (field_.empty() ? std::string("top level") : field_) + ": " + what);
  }

  // An object with exactly `keys`: unknown keys and missing keys are errors.
  void RequireObjectWithKeys(std::initializer_list<const char*> keys) const {
    if (!value_.is_object()) Fail("expected an object, found " + TypeName(value_));
    const std::set<std::string> expected(keys.begin(), keys.end());
    for (const auto& item : value_.items()) {
      if (expected.count(item.key()) == 0) {
        std::string list;
        for (const char* key : keys) list += (list.empty() ? "" : ", ") + std::string(key);
        Fail("unknown key '" + item.key() + "' (expected: " + list + ")");
      }
    }
    for (const char* key : keys) {
      if (!value_.contains(key)) Fail("missing key '" + std::string(key) + "'");
    }
  }

  Field Member(const char* key) const {
    return Field(value_.at(key), field_.empty() ? key : field_ + "." + key, source_);
  }
  Field Element(std::size_t index) const {
    return Field(value_.at(index), field_ + "[" + std::to_string(index) + "]", source_);
  }

  double Number() const {
    if (!value_.is_number()) Fail("expected a number, found " + TypeName(value_));
    const double number = value_.get<double>();
    if (!std::isfinite(number)) Fail("expected a finite number");
    return number;
  }
  int Integer() const {
    if (!value_.is_number_integer()) Fail("expected an integer, found " + TypeName(value_));
    const auto number = value_.get<std::int64_t>();
    if (number < 0 || number > std::numeric_limits<int>::max()) {
      Fail("expected a non-negative integer, found " + std::to_string(number));
    }
    return static_cast<int>(number);
  }
  std::string String() const {
    if (!value_.is_string()) Fail("expected a string, found " + TypeName(value_));
    return value_.get<std::string>();
  }
  bool Boolean() const {
    if (!value_.is_boolean()) Fail("expected true or false, found " + TypeName(value_));
    return value_.get<bool>();
  }
  std::size_t ArraySize() const {
    if (!value_.is_array()) Fail("expected an array, found " + TypeName(value_));
    return value_.size();
  }

 private:
  const Json& value_;
  std::string field_;
  const std::string& source_;
};

Eigen::Vector3d ReadXyz(const Field& field) {
  field.RequireObjectWithKeys({"x", "y", "z"});
  return Eigen::Vector3d(field.Member("x").Number(), field.Member("y").Number(),
                         field.Member("z").Number());
}

Eigen::Quaterniond ReadUnitQuaternion(const Field& field) {
  field.RequireObjectWithKeys({"x", "y", "z", "w"});
  Eigen::Quaterniond q(field.Member("w").Number(), field.Member("x").Number(),
                       field.Member("y").Number(), field.Member("z").Number());
  const double norm = q.norm();
  if (!(std::abs(norm - 1.0) <= kQuaternionNormTolerance)) {
    field.Fail("quaternion norm " + std::to_string(norm) + " is not 1 (tolerance 1e-6)");
  }
  // Keep a quaternion that is unit to machine precision bit for bit (exact round trip).
  if (std::abs(norm - 1.0) > 4.0 * std::numeric_limits<double>::epsilon()) q.normalize();
  return q;
}

void CheckCorners(const Field& field, const MarkerInfo& marker) {
  if (field.ArraySize() != 4) field.Fail("expected 4 corners");
  const std::array<Eigen::Vector3d, 4> expected = marker.CornersInMarker();
  static const char* const kNames[4] = {"top-left", "top-right", "bottom-right", "bottom-left"};
  for (std::size_t i = 0; i < 4; ++i) {
    const Field corner = field.Element(i);
    if (corner.ArraySize() != 3) corner.Fail("expected 3 numbers [x, y, z]");
    const Eigen::Vector3d value(corner.Element(0).Number(), corner.Element(1).Number(),
                                corner.Element(2).Number());
    if ((value - expected[i]).cwiseAbs().maxCoeff() > kCornerTolerance) {
      const auto& e = expected[i];
      corner.Fail("the " + std::string(kNames[i]) + " corner of a marker of size " +
                  std::to_string(marker.size) + " must be [" + std::to_string(e.x()) + ", " +
                  std::to_string(e.y()) + ", " + std::to_string(e.z()) + "] (tolerance 1e-6 m)");
    }
  }
}

MarkerInfo ReadMarker(const Field& field, int dictionary_ids) {
  field.RequireObjectWithKeys({"id", "size", "pose", "corners", "fixed"});
  MarkerInfo marker;
  marker.id = field.Member("id").Integer();
  if (marker.id >= dictionary_ids) {
    field.Member("id").Fail("id " + std::to_string(marker.id) + " is outside the dictionary (0.." +
                            std::to_string(dictionary_ids - 1) + ")");
  }
  marker.size = field.Member("size").Number();
  if (!(marker.size > 0.0)) {
    field.Member("size").Fail("expected a positive side in metres, found " +
                              std::to_string(marker.size));
  }
  const Field pose = field.Member("pose");
  pose.RequireObjectWithKeys({"position", "orientation"});
  marker.world_from_marker.translation = ReadXyz(pose.Member("position"));
  marker.world_from_marker.rotation = ReadUnitQuaternion(pose.Member("orientation"));
  CheckCorners(field.Member("corners"), marker);
  marker.fixed = field.Member("fixed").Boolean();
  return marker;
}

}  // namespace

MarkerMap ParseMarkerMapJson(const std::string& text, const std::string& source) {
  Json document;
  try {
    document = Json::parse(text);
  } catch (const Json::parse_error& error) {
    throw InputError(source, std::string("not valid JSON: ") + error.what());
  }
  const Field root(document, "", source);
  root.RequireObjectWithKeys({"format", "dictionary", "frame", "markers"});
  const std::string format = root.Member("format").String();
  if (format != kMarkerMapFormat) {
    root.Member("format").Fail("expected \"" + std::string(kMarkerMapFormat) + "\", found \"" +
                               format + "\"");
  }
  MarkerMap map;
  map.dictionary = root.Member("dictionary").String();
  if (!IsDictionaryName(map.dictionary)) {
    std::string accepted;
    for (const std::string& name : DictionaryNames()) {
      accepted += (accepted.empty() ? "" : ", ") + name;
    }
    root.Member("dictionary")
        .Fail("unknown marker dictionary \"" + map.dictionary + "\" (accepted: " + accepted + ")");
  }
  const int dictionary_ids = DictionaryFromName(map.dictionary)->bytesList.rows;
  map.frame = root.Member("frame").String();
  if (map.frame.empty()) root.Member("frame").Fail("expected a frame name, found \"\"");
  const Field markers = root.Member("markers");
  std::map<int, std::size_t> index_of_id;
  for (std::size_t i = 0; i < markers.ArraySize(); ++i) {
    const MarkerInfo marker = ReadMarker(markers.Element(i), dictionary_ids);
    const auto [it, inserted] = index_of_id.emplace(marker.id, i);
    if (!inserted) {
      markers.Element(i).Member("id").Fail("duplicate id " + std::to_string(marker.id) +
                                           " (also markers[" + std::to_string(it->second) + "])");
    }
    map.markers[marker.id] = marker;
  }
  return map;
}

std::string MarkerMapToJson(const MarkerMap& map) {
  // Laid out as in DESIGN.md (one line per pose part, corners on one line); every scalar
  // goes through the JSON library, which prints the shortest exact form of a double.
  const auto number = [](double value) { return Json(value).dump(); };
  const auto xyz = [&number](const Eigen::Vector3d& v) {
    return "{\"x\": " + number(v.x()) + ", \"y\": " + number(v.y()) + ", \"z\": " + number(v.z());
  };
  std::string text = "{\n  \"format\": " + Json(kMarkerMapFormat).dump() +
                     ",\n  \"dictionary\": " + Json(map.dictionary).dump() +
                     ",\n  \"frame\": " + Json(map.frame).dump() + ",\n  \"markers\": [";
  bool first = true;
  for (const auto& [id, marker] : map.markers) {
    const Eigen::Quaterniond& q = marker.world_from_marker.rotation;
    std::string corners;
    for (const Eigen::Vector3d& c : marker.CornersInMarker()) {
      corners += std::string(corners.empty() ? "" : ", ") + "[" + number(c.x()) + ", " +
                 number(c.y()) + ", " + number(c.z()) + "]";
    }
    text += std::string(first ? "" : ",") + "\n    {\n      \"id\": " + std::to_string(id) +
            ",\n      \"size\": " + number(marker.size) +
            ",\n      \"pose\": {\"position\": " + xyz(marker.world_from_marker.translation) +
            "},\n               \"orientation\": " + xyz(q.vec()) + ", \"w\": " + number(q.w()) +
            "}},\n      \"corners\": [" + corners +
            "],\n      \"fixed\": " + (marker.fixed ? "true" : "false") + "\n    }";
    first = false;
  }
  text += std::string(map.markers.empty() ? "" : "\n  ") + "]\n}\n";
  ParseMarkerMapJson(text, "marker map to write");  // throws when it would not read back
  return text;
}

MarkerMap ReadMarkerMapJson(const std::filesystem::path& path) {
  return ParseMarkerMapJson(ReadTextFile(path), path.string());
}

void WriteMarkerMapJson(const MarkerMap& map, const std::filesystem::path& path) {
  WriteTextFileAtomically(path, MarkerMapToJson(map));
}

}  // namespace arucoslam
