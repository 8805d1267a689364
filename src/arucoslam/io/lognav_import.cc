#include "arucoslam/io/lognav_import.h"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "arucoslam/markers/dictionary.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

using Json = nlohmann::json;

constexpr const char* kKeys[] = {"id", "pos_x", "pos_y", "pos_z", "yaw", "size"};

std::string EntryName(std::size_t index, const Json& entry) {
  std::string name = "entry " + std::to_string(index);
  if (entry.is_object() && entry.contains("id") && entry["id"].is_number_integer()) {
    name += " (id " + std::to_string(entry["id"].get<std::int64_t>()) + ")";
  }
  return name;
}

double FiniteNumber(const Json& entry, const char* key, const std::string& where,
                    const std::string& source) {
  const Json& value = entry.at(key);
  if (!value.is_number() || !std::isfinite(value.get<double>())) {
    throw InputError(source,
                     where + ": '" + key + "' must be a finite number, found " + value.dump());
  }
  return value.get<double>();
}

// One entry of the list, checked; `where` names it in errors.
MarkerInfo ReadEntry(const Json& entry, const std::string& where, const std::string& source,
                     int dictionary_ids, bool fixed) {
  if (!entry.is_object()) throw InputError(source, where + ": expected an object");
  for (const auto& item : entry.items()) {
    bool known = false;
    for (const char* key : kKeys) known = known || item.key() == key;
    if (!known) {
      throw InputError(source, where + ": unknown key '" + item.key() +
                                   "' (expected id, pos_x, pos_y, pos_z, yaw, size)");
    }
  }
  for (const char* key : kKeys) {
    if (!entry.contains(key)) throw InputError(source, where + ": missing key '" + key + "'");
  }
  const Json& id = entry["id"];
  if (!id.is_number_integer() || id.get<std::int64_t>() < 0 ||
      id.get<std::int64_t>() >= dictionary_ids) {
    throw InputError(source, where + ": 'id' must be an integer in 0.." +
                                 std::to_string(dictionary_ids - 1) + ", found " + id.dump());
  }
  MarkerInfo marker;
  marker.id = static_cast<int>(id.get<std::int64_t>());
  const double size_cm = FiniteNumber(entry, "size", where, source);
  if (!(size_cm > 0.0)) {
    throw InputError(
        source, where + ": 'size' must be positive (centimetres), found " + entry["size"].dump());
  }
  marker.size = size_cm / 100.0;
  marker.world_from_marker = LognavWorldFromMarker(
      FiniteNumber(entry, "pos_x", where, source), FiniteNumber(entry, "pos_y", where, source),
      FiniteNumber(entry, "pos_z", where, source), FiniteNumber(entry, "yaw", where, source));
  marker.fixed = fixed;
  return marker;
}

}  // namespace

Rigid3 LognavWorldFromMarker(double x, double y, double z, double yaw) {
  Eigen::Matrix3d box_from_marker;
  box_from_marker.col(0) = Eigen::Vector3d::UnitY();  // image right
  box_from_marker.col(1) = Eigen::Vector3d::UnitZ();  // image up
  box_from_marker.col(2) = Eigen::Vector3d::UnitX();  // out of the printed face
  const Eigen::Matrix3d world_from_box =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return Rigid3(Eigen::Matrix3d(world_from_box * box_from_marker), Eigen::Vector3d(x, y, z));
}

MarkerMap ParseLognavMarkers(const std::string& text, const std::string& source,
                             const LognavImportOptions& options) {
  if (!options.Check()) throw InputError(source, "no dictionary given for the import");
  const int dictionary_ids = DictionaryFromName(options.dictionary, "--dictionary")->bytesList.rows;
  Json document;
  try {
    document = Json::parse(text);
  } catch (const Json::parse_error& error) {
    throw InputError(source, std::string("not valid JSON: ") + error.what());
  }
  if (!document.is_array()) {
    throw InputError(source,
                     "expected a JSON array of markers {id, pos_x, pos_y, pos_z, yaw, "
                     "size}");
  }
  MarkerMap map;
  map.dictionary = options.dictionary;
  std::map<int, std::size_t> index_of_id;
  for (std::size_t i = 0; i < document.size(); ++i) {
    const std::string where = EntryName(i, document[i]);
    const MarkerInfo marker = ReadEntry(document[i], where, source, dictionary_ids, options.fixed);
    const auto [it, inserted] = index_of_id.emplace(marker.id, i);
    if (!inserted) {
      throw InputError(source, where + ": duplicate id " + std::to_string(marker.id) +
                                   " (also entry " + std::to_string(it->second) +
                                   "); give each marker its own id");
    }
    map.markers[marker.id] = marker;
  }
  return map;
}

MarkerMap ReadLognavMarkers(const std::filesystem::path& path, const LognavImportOptions& options) {
  return ParseLognavMarkers(ReadTextFile(path), path.string(), options);
}

}  // namespace arucoslam
