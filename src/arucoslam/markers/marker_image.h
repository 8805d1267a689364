// Printable marker images: the marker's cells with a white quiet zone around them
// (at least 2 cells wide, see DESIGN.md's pitfall on narrower margins).
#pragma once

#include <opencv2/core.hpp>

#include <string>

namespace arucoslam {

struct MarkerImageOptions {
  int marker_size_px = 600;   // side of the black square (border cells included), pixels
  double quiet_zone_cells = 2.0;  // white margin on each side, in marker cells (>= 2 advised)
  bool Check() const { return marker_size_px >= 16 && quiet_zone_cells >= 0.0; }
};

// 8-bit single-channel image of marker `id` of `dictionary_name`, white margin included.
// Throws InputError for an unknown dictionary or an id outside the dictionary.
cv::Mat DrawMarkerImage(const std::string& dictionary_name, int id,
                        const MarkerImageOptions& options = {});

// Width of the quiet zone in pixels for the given options and dictionary.
int QuietZonePixels(const std::string& dictionary_name, const MarkerImageOptions& options);

}  // namespace arucoslam
