// MarkerInitializer: the first map from two frames whose camera poses the markers give: their
// matches triangulated with the markers' relative pose, then the map moved into the marker world.
// A value says what happened: built in the world, built but not aligned, or why it refused.
#pragma once

#include <cstddef>
#include <string>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/geometry/sim3.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/slam/initializer.h"
#include "arucoslam/slam/map_initialization.h"
#include "arucoslam/slam/world_alignment.h"

namespace arucoslam {

struct MarkerInitializationOptions {
  // The two marker locations' camera centres at least this far apart, metres.
  double min_baseline_m = 0.5;
  // ... and the triangulated points' median parallax at least this, degrees.
  double min_parallax_deg = 1.0;
  // The Sim3 fit of the new map to the two marker poses (anchor outliers beyond 0.25 m, as
  // WorldAnchoringOptions' alignment).
  WorldAlignmentOptions alignment{0.0, 0.25, 0.05};

  bool Check(std::string* why = nullptr) const;
};

enum class MarkerInitializationStatus {
  kShortBaseline,  // the camera centres are too close: a later frame may do
  kRefused,        // too few good points, too little parallax, or the map failed its test
  kUnaligned,      // the map is built, but its fit to the two marker poses failed
  kInWorld,        // the map is built and moved into the marker world
};

struct MarkerInitializationResult {
  MarkerInitializationStatus status = MarkerInitializationStatus::kRefused;
  std::string message;      // what was measured, or why it refused
  InitialMapResult map;     // kUnaligned and kInWorld: the two keyframes and the point count
  double baseline_m = 0.0;  // between the two marker locations' camera centres, metres
  Sim3 world_from_map;      // kInWorld: the move applied to the map and both frames' poses
};

class MarkerInitializer {
 public:
  MarkerInitializer(const MarkerInitializationOptions& options, const InitializerOptions& two_view,
                    const InitialMapOptions& initial_map);

  // `map` must be empty; `first` and `second` have `undistorted` filled and the given marker
  // locations. On kUnaligned and kInWorld both frames are posed (in the map, or in the world)
  // as CreateInitialMap leaves them; `frame_index` is for the log.
  MarkerInitializationResult Initialize(Map& map, Frame& first, Frame& second,
                                        const Rigid3& world_from_first,
                                        const Rigid3& world_from_second,
                                        std::size_t frame_index) const;

 private:
  MarkerInitializationOptions options_;
  InitializerOptions two_view_;  // matching, reprojection gate and minimum of good points
  InitialMapOptions initial_map_;
};

}  // namespace arucoslam
