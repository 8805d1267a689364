#include "arucoslam/markers/marker_image.h"

#include <opencv2/aruco.hpp>

#include <cmath>

#include "arucoslam/markers/dictionary.h"
#include "arucoslam/util/error.h"

namespace arucoslam {

int QuietZonePixels(const std::string& dictionary_name, const MarkerImageOptions& options) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary = DictionaryFromName(dictionary_name);
  const int cells = dictionary->markerSize + 2;  // data cells plus the black border
  return static_cast<int>(
      std::lround(options.quiet_zone_cells * options.marker_size_px / static_cast<double>(cells)));
}

cv::Mat DrawMarkerImage(const std::string& dictionary_name, int id,
                        const MarkerImageOptions& options) {
  if (!options.Check()) throw InputError("--size-px", "marker image must be at least 16 px");
  const cv::Ptr<cv::aruco::Dictionary> dictionary = DictionaryFromName(dictionary_name);
  if (id < 0 || id >= dictionary->bytesList.rows) {
    throw InputError("id", "marker id " + std::to_string(id) + " is outside " + dictionary_name +
                               " (0.." + std::to_string(dictionary->bytesList.rows - 1) + ")");
  }
  cv::Mat marker;
  cv::aruco::drawMarker(dictionary, id, options.marker_size_px, marker, 1);
  const int margin = QuietZonePixels(dictionary_name, options);
  cv::Mat image;
  cv::copyMakeBorder(marker, image, margin, margin, margin, margin, cv::BORDER_CONSTANT,
                     cv::Scalar(255));
  return image;
}

}  // namespace arucoslam
