// markers.json (DESIGN.md, "Marker map") to and from a MarkerMap, with strict validation:
// every problem is an InputError naming the file and the field ("markers[2].size: ...").
#pragma once

#include <filesystem>
#include <string>

#include "arucoslam/markers/marker_map.h"

namespace arucoslam {

// The value of the "format" key this code reads and writes.
inline constexpr const char* kMarkerMapFormat = "arucoslam.markers/1";

// Tolerances of the checks, dimensionless / metres.
inline constexpr double kQuaternionNormTolerance = 1e-6;  // allowed | |q| - 1 |
inline constexpr double kCornerTolerance = 1e-6;          // corner vs size, metres

// Parses the text of a markers.json; `source` names it in errors. Rejected: text that is
// not JSON, unknown keys at any level, missing fields, wrong types, an unknown format or
// dictionary, negative or zero sizes, ids outside the dictionary, duplicate ids, corners
// that disagree with the size, a quaternion whose norm is off by more than 1e-6, values
// that are not finite. A quaternion within the tolerance is normalised.
MarkerMap ParseMarkerMapJson(const std::string& text, const std::string& source);

// The JSON text of `map` (keys in DESIGN.md's order, corners from the sizes). Doubles are
// written in the shortest form that reads back to the same value, so a write-read round
// trip is exact. Throws InputError when the map would not read back (e.g. a bad size).
std::string MarkerMapToJson(const MarkerMap& map);

// File versions: read (InputError naming `path` when missing or malformed) and write
// atomically (a reader never sees half a file).
MarkerMap ReadMarkerMapJson(const std::filesystem::path& path);
void WriteMarkerMapJson(const MarkerMap& map, const std::filesystem::path& path);

}  // namespace arucoslam
