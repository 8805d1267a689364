// MarkerMap: the known (or mapped) markers of a world, as in DESIGN.md's markers.json:
// per marker its id, side, world_from_marker pose, corners in the marker frame, fixed flag.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

struct MarkerInfo {
  int id = -1;
  double size = 0.0;  // side of the black square, metres
  Rigid3 world_from_marker;
  bool fixed = true;  // false: the SLAM may refine it, or mapped it itself

  // Corners in the marker frame in OpenCV order (top-left, top-right, bottom-right,
  // bottom-left): (-s/2, s/2, 0), (s/2, s/2, 0), (s/2, -s/2, 0), (-s/2, -s/2, 0).
  std::array<Eigen::Vector3d, 4> CornersInMarker() const;
  std::array<Eigen::Vector3d, 4> CornersInWorld() const;
};

// The largest angle between a marker's printed-side normal and the line of sight at which a
// detector still reads it: beyond it the marker is a sliver, and a detection there a misread.
inline constexpr double kMaxReadableViewAngleDeg = 85.0;

// Whether a camera centred at `camera_in_world` sees the printed side (the marker frame's +z)
// of a marker at `world_from_marker`: the cosine of the angle between that normal and the line
// of sight above `min_view_cosine` (0: anywhere in front of the marker).
bool SeesPrintedSide(const Rigid3& world_from_marker, const Eigen::Vector3d& camera_in_world,
                     double min_view_cosine);

struct MarkerMap {
  std::string dictionary = "DICT_4X4_50";
  std::string frame = "world";
  std::map<int, MarkerInfo> markers;  // keyed by id, ids unique

  const MarkerInfo* Find(int id) const {
    const auto it = markers.find(id);
    return it == markers.end() ? nullptr : &it->second;
  }
};

}  // namespace arucoslam
