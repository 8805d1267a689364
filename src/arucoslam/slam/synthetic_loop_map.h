// A drifted monocular map of a loop, for loop-closing tests and benchmarks: keyframes on the
// synthetic loop's circle look at a textured wall; points re-seen at the end are duplicates.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "arucoslam/map/map.h"
#include "arucoslam/optim/synthetic_loop.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct SyntheticLoopMapOptions {
  // The keyframes and the drift (see optim/synthetic_loop.h; default 40 keyframes on a 10 m
  // circle, 0.01 rad and 1% scale drift per step).
  SyntheticLoopOptions loop;
  int num_wall_points = 4000;  // on a wall 15-17 m from the centre, 4 m high
  int max_flipped_bits = 2;    // per observation, 0..max bits of the descriptor are flipped
  std::uint32_t seed = 11;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Nested("loop", loop);
    check.Above("num_wall_points", num_wall_points, 0);
    check.AtLeast("max_flipped_bits", max_flipped_bits, 0);
    return check.ok();
  }
};

struct SyntheticLoopMap {
  SyntheticLoop loop;                // truth and drifted estimate
  std::vector<double> local_scales;  // per keyframe: scale of the estimate around it
  std::vector<KeyframeId> keyframes;
};

// Fills an empty `map` as monocular mapping with drift would: keyframe i at the drifted
// estimate, one keypoint per visible wall point (true pixel, level 0, angle 0); a point is
// created by the first keyframe that sees it (in its drifted frame and local scale) and also
// observed by the next one; a later keyframe that sees it again creates a duplicate.
SyntheticLoopMap BuildSyntheticLoopMap(const SyntheticLoopMapOptions& options, Map* map);

// RMS distance (metres) between the keyframes' camera centres in `map` and the truth.
double KeyframeCentreRms(const Map& map, const SyntheticLoopMap& scene);

}  // namespace arucoslam
