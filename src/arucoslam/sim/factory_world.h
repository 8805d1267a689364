// The procedural factory hall (low-texture corridor, aisles of racks, machines, docks with
// ArUco markers): BuildFactoryWorld lays it out from a seed, WriteFactoryWorld writes it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/io/path_json.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/sim/procedural_texture.h"

namespace arucoslam {

struct FactoryOptions {
  std::uint32_t seed = 1;                        // everything random comes from it
  int aisles = 3;                                // parallel aisles between rack rows, [1, 8]
  double aisle_length_m = 20.0;                  // length of the racks along an aisle, [6, 60] m
  TextureLevel texture = TextureLevel::kMedium;  // clutter and surface detail
  bool markers = true;                           // ArUco markers at the docks
  double marker_size_m = 0.2;                    // side of the black square, (0.05, 1] m
  std::string dictionary = "DICT_4X4_50";
  int markers_per_dock = 1;      // side by side on the dock board, [1, 4]
  // One more marker board at each end of the corridor, on its long (y = 0) wall 1.8 m from
  // the end wall, facing into the corridor: the wall a robot faces while it turns there.
  // Ids after the docks'. Only with markers.
  bool corridor_end_markers = false;
  // Marker boards along the same wall every this many metres (0: none, the docks only), from
  // the first corridor-end position to the last, boards that would cover a pillar left out;
  // ids after the docks'. As the ArucoSLAM authors' simulation (LOGNAV) lines one wall: a
  // marker every metre; the docks alone leave the corridor's 20 m without one. Only with
  // markers.
  double wall_marker_spacing_m = 1.0;
  int marker_image_px = 240;     // marker PNG: side of the black square, pixels
  double camera_height_m = 0.6;  // marker centres and the route's camera, [0.3, 1.0] m

  bool Check(std::string* why = nullptr) const;
};

// "low", "medium", "high" <-> TextureLevel; throws InputError("--texture", ...) otherwise.
TextureLevel TextureLevelFromName(const std::string& name);
std::string TextureLevelName(TextureLevel level);

// One visual of a model (collisions mirror it). Sizes in metres; a cylinder's size is
// (2 radius, 2 radius, length).
struct FactoryVisual {
  enum class Shape { kBox, kCylinder } shape = Shape::kBox;
  std::string name;
  Rigid3 model_from_visual;
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  cv::Scalar colour{1, 1, 1};  // RGB 0..1 (diffuse; ambient the same)
  std::string texture;         // "textures/<name>.png" relative to world.sdf, or empty
};

struct FactoryModel {
  std::string name;
  Rigid3 world_from_model;
  std::vector<FactoryVisual> visuals;
};

// A docking station: where a robot parks facing a wall, markers on the board above it.
struct FactoryDock {
  std::string name;
  Eigen::Vector2d front = Eigen::Vector2d::Zero();   // floor point 1 m in front of the board
  Eigen::Vector2d facing = Eigen::Vector2d::Zero();  // unit: from the board toward the robot
  std::vector<int> marker_ids;
  bool on_default_route = false;
};

struct FactoryWorld {
  FactoryOptions options;
  double hall_length_m = 0.0;               // along world x
  double hall_width_m = 0.0;                // along world y
  std::vector<FactoryModel> models;         // everything but the markers
  std::map<std::string, cv::Mat> textures;  // "textures/<name>.png" -> BGR image
  MarkerMap markers;                        // world_from_marker of every dock marker
  std::vector<FactoryDock> docks;
  PathSpec default_route;  // visits docks, loops back to its start, has a U-turn
};

// Lays out the factory. Throws InputError when the options are out of range or the
// dictionary has too few ids for the docks' markers.
FactoryWorld BuildFactoryWorld(const FactoryOptions& options);

// The SDF 1.9 text of the world (markers inlined as MarkerModelSdf models).
std::string FactoryWorldSdf(const FactoryWorld& world);

// Writes into the existing folder `dir`: world.sdf, textures/*.png, markers/<id>.png,
// markers.json and path.json (the default route).
void WriteFactoryWorld(const FactoryWorld& world, const std::filesystem::path& dir);

}  // namespace arucoslam
