// Two-view motion of a forward-looking camera on a wheeled vehicle: it turns about the floor's
// normal and moves along the chord of its arc, so only the turn angle is unknown (and the scale).
// With a narrow baseline the free essential matrix trades turning for sideways motion; this
// model has no sideways motion to trade.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

struct VehicleTwoViewOptions {
  // Turn angles searched: centre +- range, in steps (radians).
  double angle_range_rad = 0.35;
  double angle_step_rad = 0.0005;
  // Sampson errors (pixels at focal length `focal_px`) are truncated here: outliers count
  // as this much and no more.
  double max_error_px = 4.0;
};

struct VehicleTwoViewResult {
  // VehicleMotion(up, angle_rad): unit baseline.
  Rigid3 cam2_from_cam1;
  double angle_rad = 0.0;
  double cost = 0.0;  // sum of truncated squared Sampson errors, pixels^2
  int num_inliers = 0;
};

// cam2_from_cam1 of a camera that turns by `angle_rad` about unit `up` (camera 2's
// orientation in camera 1: a right-hand turn about up) and moves a unit distance along the
// chord of that arc.
Rigid3 VehicleMotion(const Eigen::Vector3d& up, double angle_rad);

// The turn angle near `angle_centre_rad` whose vehicle motion best explains the
// correspondences (normalised image coordinates x1[i] <-> x2[i]), searched on a grid.
// `up` is the floor normal in camera 1 coordinates (unit; (0, -1, 0) for a level camera).
VehicleTwoViewResult SolveVehicleTwoView(const std::vector<Eigen::Vector2d>& x1,
                                         const std::vector<Eigen::Vector2d>& x2,
                                         const Eigen::Vector3d& up, double angle_centre_rad,
                                         double focal_px,
                                         const VehicleTwoViewOptions& options = {});

// The part of `rotation` about unit `axis` (swing-twist decomposition), in (-pi, pi].
double TwistAngle(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& axis);

}  // namespace arucoslam
