// World alignment: the Sim(3) world_from_map that carries a monocular keypoint map (arbitrary
// frame and scale) into the marker world, from keyframes whose world pose markers gave.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "arucoslam/geometry/sim3.h"
#include "arucoslam/map/ids.h"
#include "arucoslam/map/map_data.h"
#include "arucoslam/map/marker_landmark.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

// One keyframe seen in both frames: its keypoint-map pose and its world pose from markers
// (markers/camera_locator.h LocateCamera).
struct WorldAnchor {
  KeyframeId keyframe;    // for the caller's bookkeeping only
  Rigid3 cam_from_map;    // keyframe pose in the keypoint map
  Rigid3 world_from_cam;  // from the markers
  // The marker pose rests on one marker whose IPPE solutions were ambiguous.
  bool ambiguous = false;
  // Only for a single anchor: the distance from the camera to the marker it saw, in map
  // units (e.g. the median depth of the map points on or around the marker) and in metres
  // (from the marker pose). 0 when unknown.
  double marker_depth_in_map = 0.0;
  double marker_depth_m = 0.0;
};

struct WorldAlignmentOptions {
  // Weight of an ambiguous anchor relative to an unambiguous one, in [0, 1]; 0 leaves
  // ambiguous anchors out (their pose may be IPPE's mirrored solution).
  double ambiguous_weight = 0.0;
  // An anchor whose camera centre lands farther than this from its marker position after
  // alignment is an outlier (metres, world frame).
  double outlier_threshold_m = 0.10;
  // The map's camera centres are treated as collinear when the second eigenvalue of their
  // scatter (a squared spread) is below this fraction of the first; the rotation about that line
  // then comes from averaging the anchors' orientations instead of from the centres alone.
  double collinear_ratio = 0.05;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.InRange("ambiguous_weight", ambiguous_weight, 0.0, 1.0, Interval::kClosed);
    check.Above("outlier_threshold_m", outlier_threshold_m, 0.0);
    check.InRange("collinear_ratio", collinear_ratio, 0.0, 1.0, Interval::kClosedOpen);
    return check.ok();
  }
};

enum class WorldAlignmentMethod {
  kNone,
  kCentres,                 // weighted Umeyama over >= 3 non-collinear camera centres
  kOrientationsAndCentres,  // rotation averaged from anchor orientations; scale, shift from centres
  kSingleAnchor,            // one pose plus the marker's depth ratio for the scale
};

struct WorldAlignment {
  bool success = false;
  std::string failure;  // why not (empty on success)
  Sim3 world_from_map;
  WorldAlignmentMethod method = WorldAlignmentMethod::kNone;
  std::vector<bool> inliers;  // per anchor; false for outliers and left-out anchors
  int num_inliers = 0;
  double rms_m = 0.0;  // camera-centre residual over the inliers, metres
};

// What is possible: two or more anchors with distinct centres determine scale, rotation and
// translation (two: from their orientations and the baseline; three or more non-collinear:
// from the centres). One outlier among three or more anchors is found by leaving each out.
// A single anchor gives rotation and translation; its scale only with both marker depths.
WorldAlignment EstimateWorldFromMap(const std::vector<WorldAnchor>& anchors,
                                    const WorldAlignmentOptions& options = {});

// Moves every keyframe and map point of `map` by world_from_map (points' normals and
// distance ranges recomputed) and, when given, every non-fixed marker of `markers`. With
// `stay`: those keyframes, and the points one of them observes, do not move (a part of the
// map already in the world, e.g. a merged map not yet linked to the rest).
void ApplyWorldAlignment(const Sim3& world_from_map, MapData* map,
                         MarkerLandmarks* markers = nullptr,
                         const std::set<KeyframeId>* stay = nullptr);

}  // namespace arucoslam
