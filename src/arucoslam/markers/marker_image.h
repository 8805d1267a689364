// Printable marker images: the marker's cells with a white quiet zone around them
// (at least 2 cells wide, see DESIGN.md's pitfall on narrower margins).
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct MarkerImageOptions {
  int marker_size_px = 600;   // side of the black square (border cells included), pixels
  double quiet_zone_cells = 2.0;  // white margin on each side, in marker cells (>= 2 advised)
  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("marker_size_px", marker_size_px, 16);
    check.AtLeast("quiet_zone_cells", quiet_zone_cells, 0.0);
    return check.ok();
  }
};

// 8-bit single-channel image of marker `id` of `dictionary_name`, white margin included.
// Throws InputError for an unknown dictionary or an id outside the dictionary.
cv::Mat DrawMarkerImage(const std::string& dictionary_name, int id,
                        const MarkerImageOptions& options = {});

// Width of the quiet zone in pixels for the given options and dictionary.
int QuietZonePixels(const std::string& dictionary_name, const MarkerImageOptions& options);

}  // namespace arucoslam
