// Two-view triangulation: linear (DLT) point from two normalised observations and known
// poses, plus the checks a new point must pass (in front of both cameras, parallax, error).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

// The point (in the world frame) whose projections best fit `normalised1` in camera 1 and
// `normalised2` in camera 2 in the algebraic (DLT) sense. Observations are undistorted
// normalised coordinates (x/z, y/z). nullopt for a point at infinity or non-finite result.
std::optional<Eigen::Vector3d> TriangulateDlt(const Rigid3& cam1_from_world,
                                              const Rigid3& cam2_from_world,
                                              const Eigen::Vector2d& normalised1,
                                              const Eigen::Vector2d& normalised2);

// Angle (radians, [0, pi]) at `p_in_world` between the rays to the two camera centres.
double ParallaxAngle(const Eigen::Vector3d& p_in_world, const Eigen::Vector3d& centre1_in_world,
                     const Eigen::Vector3d& centre2_in_world);

// Squared reprojection error in pixels of a point in a camera's frame against a normalised
// observation (normalised error times (fx, fy)); infinity when the point is not in front.
double SquaredReprojectionErrorPx(const Eigen::Vector3d& p_in_cam,
                                  const Eigen::Vector2d& normalised, double fx, double fy);

// Geometry of one triangulated point with respect to both views.
struct TriangulationQuality {
  double depth1 = 0.0;        // z in camera 1 (metres or map units)
  double depth2 = 0.0;        // z in camera 2
  double parallax_rad = 0.0;  // ParallaxAngle
  // Squared reprojection errors in pixels, using the focal lengths given (normalised error
  // times (fx, fy)); infinity when the point is behind that camera.
  double error1_sq_px = 0.0;
  double error2_sq_px = 0.0;
};

TriangulationQuality EvaluateTriangulation(
    const Eigen::Vector3d& p_in_world, const Rigid3& cam1_from_world, const Rigid3& cam2_from_world,
    const Eigen::Vector2d& normalised1, const Eigen::Vector2d& normalised2, double fx, double fy);

}  // namespace arucoslam
