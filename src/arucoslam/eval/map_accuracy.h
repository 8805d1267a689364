// Map accuracy in a simulated world: the distance from each estimated map point (after the
// trajectory's alignment) to the nearest true surface of boxes, planes and cylinders.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arucoslam/geometry/sim3.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

enum class SurfaceShape { kBox, kPlane, kCylinder };

// One solid or sheet of the true world, in its own frame (SDF's conventions):
//   box: centred at the origin, full side lengths `box_size` (x, y, z);
//   plane: the rectangle |x| <= plane_size.x/2, |y| <= plane_size.y/2 at z = 0 (a zero
//          side makes it unbounded in that direction);
//   cylinder: axis z, centred at the origin, `radius`, full `length`, closed by its caps.
struct SurfacePrimitive {
  SurfaceShape shape = SurfaceShape::kBox;
  Rigid3 world_from_shape;
  Eigen::Vector3d box_size = Eigen::Vector3d::Zero();    // m
  Eigen::Vector2d plane_size = Eigen::Vector2d::Zero();  // m
  double radius = 0.0;                                   // m
  double length = 0.0;                                   // m
};

// Distance (m, >= 0) from a world point to the primitive's surface; a point inside a solid
// is at the distance of its nearest face.
double DistanceToSurface(const SurfacePrimitive& primitive, const Eigen::Vector3d& p_in_world);
// Smallest distance over all primitives; +infinity when there are none.
double DistanceToNearestSurface(const std::vector<SurfacePrimitive>& primitives,
                                const Eigen::Vector3d& p_in_world);

struct MapAccuracyOptions {
  double inlier_distance = 0.05;  // m, "within" threshold for fraction_within

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("inlier_distance", inlier_distance, 0.0);
    return check.ok();
  }
};

struct MapAccuracy {
  std::size_t num_points = 0;
  double median = 0.0;           // m
  double percentile_90 = 0.0;    // m
  double mean = 0.0;             // m
  double fraction_within = 0.0;  // of points closer than inlier_distance
  double inlier_distance = 0.0;  // m, the threshold used
};

// Points are in the estimate's frame; `gt_from_est` (the trajectory's alignment, scale
// included) carries them into the world first.
MapAccuracy ComputeMapAccuracy(const std::vector<Eigen::Vector3d>& points_in_est,
                               const Sim3& gt_from_est,
                               const std::vector<SurfacePrimitive>& primitives,
                               const MapAccuracyOptions& options);

}  // namespace arucoslam
