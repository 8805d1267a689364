#include "arucoslam/eval/map_accuracy.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "arucoslam/eval/statistics.h"

namespace arucoslam {
namespace {

double BoxDistance(const Eigen::Vector3d& half, const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = p.cwiseAbs() - half;
  if ((q.array() <= 0.0).all()) return -q.maxCoeff();  // inside: nearest face
  return q.cwiseMax(0.0).norm();
}

double PlaneDistance(const Eigen::Vector2d& size, const Eigen::Vector3d& p) {
  const double dx = size.x() > 0.0 ? std::max(std::abs(p.x()) - 0.5 * size.x(), 0.0) : 0.0;
  const double dy = size.y() > 0.0 ? std::max(std::abs(p.y()) - 0.5 * size.y(), 0.0) : 0.0;
  return std::sqrt(dx * dx + dy * dy + p.z() * p.z());
}

double CylinderDistance(double radius, double length, const Eigen::Vector3d& p) {
  const double radial = std::hypot(p.x(), p.y()) - radius;
  const double axial = std::abs(p.z()) - 0.5 * length;
  if (radial <= 0.0 && axial <= 0.0) return std::min(-radial, -axial);
  return std::hypot(std::max(radial, 0.0), std::max(axial, 0.0));
}

}  // namespace

double DistanceToSurface(const SurfacePrimitive& primitive, const Eigen::Vector3d& p_in_world) {
  const Eigen::Vector3d p = primitive.world_from_shape.Inverse() * p_in_world;
  switch (primitive.shape) {
    case SurfaceShape::kBox:
      return BoxDistance(0.5 * primitive.box_size, p);
    case SurfaceShape::kPlane:
      return PlaneDistance(primitive.plane_size, p);
    case SurfaceShape::kCylinder:
      return CylinderDistance(primitive.radius, primitive.length, p);
  }
  return std::numeric_limits<double>::infinity();
}

double DistanceToNearestSurface(const std::vector<SurfacePrimitive>& primitives,
                                const Eigen::Vector3d& p_in_world) {
  double best = std::numeric_limits<double>::infinity();
  for (const SurfacePrimitive& primitive : primitives) {
    best = std::min(best, DistanceToSurface(primitive, p_in_world));
  }
  return best;
}

MapAccuracy ComputeMapAccuracy(const std::vector<Eigen::Vector3d>& points_in_est,
                               const Sim3& gt_from_est,
                               const std::vector<SurfacePrimitive>& primitives,
                               const MapAccuracyOptions& options) {
  if (!options.Check()) throw std::invalid_argument("MapAccuracyOptions: invalid");
  MapAccuracy result;
  result.inlier_distance = options.inlier_distance;
  result.num_points = points_in_est.size();
  if (points_in_est.empty()) return result;
  std::vector<double> distances;
  distances.reserve(points_in_est.size());
  std::size_t within = 0;
  double sum = 0.0;
  for (const Eigen::Vector3d& point : points_in_est) {
    const double d = DistanceToNearestSurface(primitives, gt_from_est * point);
    distances.push_back(d);
    sum += d;
    if (d <= options.inlier_distance) ++within;
  }
  result.mean = sum / static_cast<double>(distances.size());
  result.median = Percentile(distances, 50.0);
  result.percentile_90 = Percentile(distances, 90.0);
  result.fraction_within = static_cast<double>(within) / static_cast<double>(distances.size());
  return result;
}

}  // namespace arucoslam
