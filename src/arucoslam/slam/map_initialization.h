// CreateInitialMap: turns a successful two-view initialisation into the first two keyframes
// and their map points, refines them by bundle adjustment and rescales to median depth 1.
#pragma once

#include <string>

#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/optim/bundle_adjustment.h"
#include "arucoslam/slam/initializer.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct InitialMapOptions {
  BundleAdjustmentOptions bundle_adjustment;  // refinement of both keyframes and the points
  // After refinement the map is rejected when fewer points than this keep both views inside
  // the chi-square test (the tracker needs that many to continue).
  int min_points = 50;
  // The motion between the two keyframes is known (e.g. from two marker poses): refinement
  // moves the points only.
  bool hold_motion = false;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Nested("bundle_adjustment", bundle_adjustment);
    check.AtLeast("min_points", min_points, 0);
    return check.ok();
  }
};

struct InitialMapResult {
  bool success = false;
  std::string message;  // why it was rejected
  KeyframeId first;
  KeyframeId second;
  int num_points = 0;
};

// `map` must be empty. `frame1` gets the identity pose, `frame2` the initialiser's motion;
// both get their map_point_ids filled (frame2 is ready for Tracker::Start). On failure the
// map is left empty and the frames' poses are cleared.
InitialMapResult CreateInitialMap(Map& map, Frame& frame1, Frame& frame2,
                                  const InitializationResult& initialization,
                                  const InitialMapOptions& options = {});

}  // namespace arucoslam
