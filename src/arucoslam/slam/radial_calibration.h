// RadialCalibration: refines the camera's radial distortion from the map itself, as
// structure-from-motion refines intrinsics: a rectification or calibration that leaves a
// little radial distortion makes a monocular map's scale drift in turns.
#pragma once

#include <optional>
#include <string>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/map/map.h"
#include "arucoslam/optim/bundle_adjustment.h"

namespace arucoslam {

struct RadialCalibrationOptions {
  // Refine the radial coefficient at all.
  bool enabled = true;
  // First attempt once the map holds this many keyframes; each later one at twice the count
  // of the one before, up to max_attempts.
  int first_keyframes = 12;
  int max_attempts = 3;
  // A correction is kept when the whole-map cost falls by at least this fraction with it
  // (compared with the same solve without it) ...
  double min_cost_decrease = 0.01;
  // ... and stays within this magnitude (normalised coordinates).
  double max_abs_k = 0.1;
  // The whole-map solves.
  BundleAdjustmentOptions solver = [] {
    BundleAdjustmentOptions options;
    options.max_iterations = 30;
    return options;
  }();

  bool Check(std::string* why = nullptr) const;
};

struct RadialCalibrationStep {
  bool attempted = false;
  bool applied = false;
  double k = 0.0;                  // the correction found (applied or not)
  double cost_without = 0.0;       // whole-map cost of the solve without the radial term
  double cost_with = 0.0;          // ... and with it
  std::string message;
};

class RadialCalibration {
 public:
  explicit RadialCalibration(const RadialCalibrationOptions& options = {}) : options_(options) {}

  // Called after a keyframe was mapped (mapping thread). When an attempt is due: solves the
  // whole map with and without the radial term; when the term pays, writes the map's poses
  // and points, recalibrates every keyframe and returns the refined camera in `camera`.
  RadialCalibrationStep MaybeRefine(Map& map, CameraModel* camera);

  int num_applied() const { return num_applied_; }

 private:
  RadialCalibrationOptions options_;
  int num_attempts_ = 0;
  int num_applied_ = 0;
};

}  // namespace arucoslam
