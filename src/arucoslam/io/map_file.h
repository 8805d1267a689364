// Map files: a versioned, checksummed binary snapshot of a map (cameras, keyframes with their
// features and poses, map points, spanning tree) that loads back into an equal MapData.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "arucoslam/map/map.h"
#include "arucoslam/map/map_data.h"

namespace arucoslam {

// Layout of format version 3 (all numbers little-endian, doubles as IEEE-754 bit patterns,
// so poses and positions load back bit-exact):
//   header  : 16 magic bytes "ARUCOSLAM-MAP\r\n\x1a", u32 endianness marker 0x01020304,
//             u32 format version, u64 payload size in bytes;
//   payload : sections "META" (u32 flags: bit 0 = the map is in the marker world frame with
//             metric scale), "CAMS" (distinct cameras), "KFRM" (keyframes: ids, timestamp, pose,
//             camera index, keypoints with octave/angle/response, descriptors, undistorted
//             coordinates, pyramid tables, image size, map point id per keypoint, markers),
//             "MPTS" (points: id, position, descriptor, observations, reference keyframe,
//             normal, distance range, counters), "TREE" (spanning-tree parent per keyframe);
//   trailer : u64 FNV-1a (64 bit) of every byte before it.
// Covisibility weights are not stored: by definition they count the points two keyframes
// share, so loading rebuilds them exactly from the observations. The spanning tree depends
// on the map's history and is stored. Ids are kept; the loaded map hands out new ids above
// the largest loaded one. A camera is u32 width, height, 4 doubles fx fy cx cy, u8 distortion
// model, 14 doubles of distortion (OpenCV's order), double rate. Version 2 (still read) stored 5
// distortion doubles and knew the models up to equidistant; version 1 (no "META") is refused
// like any other version.
inline constexpr std::uint32_t kMapFormatVersion = 3;
inline constexpr std::uint32_t kOldestMapFormatVersion = 2;

// What a map file records about its map beyond keyframes and points.
struct MapFileInfo {
  // The map is in the marker world frame (metric): marker poses relocalise into it.
  bool world_aligned = false;
};

// The bytes of a map file for `data`. Throws std::invalid_argument for descriptors that are
// not 32-byte CV_8U rows.
std::string SerializeMap(const MapData& data, const MapFileInfo& info = {});

// Decodes the bytes of a map file; `source` names them in errors. Throws InputError(source,
// ...) for: wrong magic ("not an arucoslam map"), a format version outside
// kOldestMapFormatVersion..kMapFormatVersion, a truncated file
// ("ends after N bytes, expected M"), trailing bytes, a checksum mismatch, or content that is
// inconsistent (unknown ids, broken spanning tree, observations not mirrored). `info`, when
// given, receives the file's MapFileInfo.
MapData DeserializeMap(std::string_view bytes, const std::string& source,
                       MapFileInfo* info = nullptr);

// Writes the map file atomically (temporary file + rename). Throws InputError naming `path`
// when the folder is not writable.
void SaveMapFile(const MapData& data, const std::filesystem::path& path,
                 const MapFileInfo& info = {});
// Same for a shared Map: serialises under one read lock, writes after releasing it.
void SaveMapFile(const Map& map, const std::filesystem::path& path, const MapFileInfo& info = {});

// Reads a map file; throws InputError naming `path` when it is missing or bad (see above).
MapData LoadMapFile(const std::filesystem::path& path, MapFileInfo* info = nullptr);
// Replaces the content of `map` with the file's map (all or nothing: `map` is untouched
// when loading throws).
void LoadMapFile(const std::filesystem::path& path, Map& map, MapFileInfo* info = nullptr);

// FNV-1a, 64 bit, of `bytes` (the trailer of a map file).
std::uint64_t Fnv1a64(std::string_view bytes);

}  // namespace arucoslam
