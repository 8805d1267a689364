// Import of the FURG LOGNAV marker list (a JSON array of {id, pos_x, pos_y, pos_z, yaw,
// size[cm]}, vertical markers) into a MarkerMap; errors name the file and the entry.
#pragma once

#include <filesystem>
#include <string>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct LognavImportOptions {
  std::string dictionary = "DICT_4X4_50";  // the list does not say; its users detect 4x4_50
  bool fixed = true;                       // value of MarkerInfo::fixed for every marker

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Require(!dictionary.empty(), "dictionary", "non-empty");
    return check.ok();
  }
};

// world_from_marker of a LOGNAV entry. Their Gazebo model is a box thin along its own x
// axis, posed `x y z 0 0 yaw`, printed on its +x face with the image upright (up = +z) and
// read unmirrored from in front (image right = box +y). So, in the OpenCV marker frame:
// marker z (out of the face) = (cos yaw, sin yaw, 0), marker y = world z (up), marker x =
// (-sin yaw, cos yaw, 0); the origin is (x, y, z), the marker centre (their printed face
// sits 0.1 mm in front of it, which is neglected).
Rigid3 LognavWorldFromMarker(double x, double y, double z, double yaw);

// Parses the text of a LOGNAV list; `source` names it in errors. Every entry needs exactly
// the six keys with numbers (id a non-negative integer inside the dictionary, size > 0 in
// centimetres); ids must be unique. Sizes are converted to metres.
MarkerMap ParseLognavMarkers(const std::string& text, const std::string& source,
                             const LognavImportOptions& options = {});
MarkerMap ReadLognavMarkers(const std::filesystem::path& path,
                            const LognavImportOptions& options = {});

}  // namespace arucoslam
