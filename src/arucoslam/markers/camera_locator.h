// Camera pose in the world from one image's marker detections and a known MarkerMap:
// all visible known corners in one PnP (RANSAC over hypotheses), refined by Levenberg-Marquardt.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct CameraLocatorOptions {
  double inlier_threshold_px = 3.0;  // a corner is an inlier within this reprojection error
  int ransac_iterations = 200;       // RANSAC PnP iterations when several markers are seen
  double ransac_confidence = 0.999;  // in (0, 1)
  int min_inlier_corners = 4;        // fewer inliers: no pose
  int refine_max_iterations = 30;    // Levenberg-Marquardt iterations (0: no refinement)
  // A pose that would show a detected marker from behind, or more edge-on than this angle
  // between its printed side's normal and the line of sight, explains none of its corners:
  // no detector reads a marker there, but a misread sliver fits such a degenerate pose.
  double max_view_angle_deg = kMaxReadableViewAngleDeg;  // (0, 90]
  MarkerPoseOptions marker_pose;                         // per-marker IPPE and its ambiguity test

  bool Check(std::string* why = nullptr) const;
};

struct LocateQuality {
  double reprojection_rms_px = 0.0;  // over inlier corners, pixels
  int num_markers = 0;               // known markers with at least one inlier corner
  int num_corners = 0;               // known corners given to the PnP
  int num_inlier_corners = 0;
  // True when the pose rests on one marker whose IPPE solutions are ambiguous: the
  // alternative pose below then explains the image almost as well.
  bool ambiguous = false;
  double error_ratio = 0.0;         // one marker: IPPE best / second error; several: 0
  double alternative_rms_px = 0.0;  // one marker: corner RMS of the alternative, pixels
};

struct CameraLocation {
  bool found = false;
  std::string failure;  // why not found (empty when found)
  Rigid3 world_from_cam;
  std::optional<Rigid3> alternative_world_from_cam;  // one marker only: IPPE's other solution
  LocateQuality quality;
  std::vector<int> marker_ids;          // known markers used (with inliers), ascending
  std::vector<int> unknown_marker_ids;  // detected but absent from the map
};

// How a pose predicted from the camera's motion settles a one-marker ambiguity
// (ResolveAmbiguity): a solution is taken when it lies within both gates of the prediction
// while the other lies beyond min_disagreement times a gate (rotation or position).
struct AmbiguityPriorGates {
  double max_rotation_deg = 4.0;
  double max_position_m = 0.2;
  double min_disagreement = 2.0;  // > 1

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("max_rotation_deg", max_rotation_deg, 0.0);
    check.Above("max_position_m", max_position_m, 0.0);
    check.Above("min_disagreement", min_disagreement, 1.0);
    return check.ok();
  }
};

// Never throws for expected failures (no known marker, too few inliers): `found` is false
// and `failure` says why. Marker sizes come from the map.
CameraLocation LocateCamera(const std::vector<MarkerDetection>& detections, const MarkerMap& map,
                            const CameraModel& camera, const CameraLocatorOptions& options = {});

// Which solution of an ambiguous one-marker location a prediction settles on.
enum class AmbiguityChoice { kNone, kBest, kAlternative };

// Of an ambiguous one-marker location (alternative_world_from_cam set), the solution that
// agrees with `predicted_world_from_cam` while the other clearly does not; kNone when
// neither or both agree, or the location has no alternative.
AmbiguityChoice ResolveAmbiguity(const CameraLocation& location,
                                 const Rigid3& predicted_world_from_cam,
                                 const AmbiguityPriorGates& gates = {});
// The same from a predicted orientation alone (world_from_cam rotation), e.g. that of a
// keypoint map whose scale and position in the world are not known yet: the rotation gate
// and min_disagreement of `gates` apply.
AmbiguityChoice ResolveAmbiguityByRotation(const CameraLocation& location,
                                           const Eigen::Quaterniond& predicted_world_from_cam,
                                           const AmbiguityPriorGates& gates = {});
// The pose of `choice` (kNone: nullopt).
std::optional<Rigid3> ChosenPose(const CameraLocation& location, AmbiguityChoice choice);

}  // namespace arucoslam
