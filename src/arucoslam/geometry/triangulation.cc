#include "arucoslam/geometry/triangulation.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

namespace arucoslam {

std::optional<Eigen::Vector3d> TriangulateDlt(const Rigid3& cam1_from_world,
                                              const Rigid3& cam2_from_world,
                                              const Eigen::Vector2d& normalised1,
                                              const Eigen::Vector2d& normalised2) {
  Eigen::Matrix<double, 3, 4> p1, p2;
  p1 << cam1_from_world.RotationMatrix(), cam1_from_world.translation;
  p2 << cam2_from_world.RotationMatrix(), cam2_from_world.translation;
  Eigen::Matrix4d a;
  a.row(0) = normalised1.x() * p1.row(2) - p1.row(0);
  a.row(1) = normalised1.y() * p1.row(2) - p1.row(1);
  a.row(2) = normalised2.x() * p2.row(2) - p2.row(0);
  a.row(3) = normalised2.y() * p2.row(2) - p2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(a, Eigen::ComputeFullV);
  const Eigen::Vector4d homogeneous = svd.matrixV().col(3);
  if (!homogeneous.allFinite() || std::abs(homogeneous(3)) < 1e-12 * homogeneous.head<3>().norm()) {
    return std::nullopt;
  }
  const Eigen::Vector3d point = homogeneous.head<3>() / homogeneous(3);
  if (!point.allFinite()) return std::nullopt;
  return point;
}

double ParallaxAngle(const Eigen::Vector3d& p_in_world, const Eigen::Vector3d& centre1_in_world,
                     const Eigen::Vector3d& centre2_in_world) {
  const Eigen::Vector3d ray1 = p_in_world - centre1_in_world;
  const Eigen::Vector3d ray2 = p_in_world - centre2_in_world;
  // atan2 of |cross| and dot stays accurate for tiny angles (acos of a cosine does not).
  return std::atan2(ray1.cross(ray2).norm(), ray1.dot(ray2));
}

double SquaredReprojectionErrorPx(const Eigen::Vector3d& p_in_cam,
                                  const Eigen::Vector2d& normalised, double fx, double fy) {
  if (p_in_cam.z() <= 0.0) return std::numeric_limits<double>::infinity();
  const double ex = fx * (p_in_cam.x() / p_in_cam.z() - normalised.x());
  const double ey = fy * (p_in_cam.y() / p_in_cam.z() - normalised.y());
  return ex * ex + ey * ey;
}

TriangulationQuality EvaluateTriangulation(
    const Eigen::Vector3d& p_in_world, const Rigid3& cam1_from_world, const Rigid3& cam2_from_world,
    const Eigen::Vector2d& normalised1, const Eigen::Vector2d& normalised2, double fx, double fy) {
  const Eigen::Vector3d p_in_cam1 = cam1_from_world * p_in_world;
  const Eigen::Vector3d p_in_cam2 = cam2_from_world * p_in_world;
  TriangulationQuality quality;
  quality.depth1 = p_in_cam1.z();
  quality.depth2 = p_in_cam2.z();
  quality.parallax_rad = ParallaxAngle(p_in_world, cam1_from_world.Inverse().translation,
                                       cam2_from_world.Inverse().translation);
  quality.error1_sq_px = SquaredReprojectionErrorPx(p_in_cam1, normalised1, fx, fy);
  quality.error2_sq_px = SquaredReprojectionErrorPx(p_in_cam2, normalised2, fx, fy);
  return quality;
}

}  // namespace arucoslam
