// MarkerOnlyRun: the camera pose of every frame from the known markers it sees alone
// (detect, then PnP on all known corners) — no keypoints, no SLAM. A reference row for the
// experiments: it shows what the marker map gives where markers are in view.
#pragma once

#include <cstddef>
#include <string>

#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/markers/preprocess.h"
#include "arucoslam/util/option_check.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

struct MarkerOnlyOptions {
  PreprocessOptions preprocess;
  DetectorOptions detector;  // its dictionary is replaced by the marker map's
  CameraLocatorOptions locator;
  // Frames whose pose rests on one ambiguous marker are left out (no pose) when true.
  bool skip_ambiguous = true;
  bool progress = true;  // a progress line on stderr

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Nested("preprocess", preprocess);
    check.Nested("locator", locator);
    return check.ok();
  }
};

struct MarkerOnlyResult {
  Trajectory trajectory;          // world_from_cam of every frame with a pose
  std::size_t frames = 0;
  std::size_t frames_with_markers = 0;  // at least one known marker detected
  std::size_t ambiguous_skipped = 0;
  TimingStats detection_ms;       // per frame: preprocessing + detection
  TimingStats locate_ms;          // per frame with markers: PnP
};

MarkerOnlyResult RunMarkerOnly(const Dataset& dataset, const MarkerMap& marker_map,
                               const MarkerOnlyOptions& options = {});

}  // namespace arucoslam
