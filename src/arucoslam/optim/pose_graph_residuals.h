// Residuals of the Sim3 pose graph, templated on the scalar so that a solver can
// differentiate them automatically: relative-pose error in the Sim3 tangent, absolute priors.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace arucoslam {
namespace pose_graph_internal {

template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;
template <typename T>
using Mat3 = Eigen::Matrix<T, 3, 3>;

// A similarity x -> scale * rotation * x + translation on any scalar type.
template <typename T>
struct SimilarityT {
  T scale;
  Eigen::Quaternion<T> rotation;
  Vec3<T> translation;

  SimilarityT operator*(const SimilarityT& other) const {
    return {scale * other.scale, rotation * other.rotation,
            scale * (rotation * other.translation) + translation};
  }
  SimilarityT Inverse() const {
    const Eigen::Quaternion<T> inverse_rotation = rotation.conjugate();
    const T inverse_scale = T(1.0) / scale;
    return {inverse_scale, inverse_rotation, -inverse_scale * (inverse_rotation * translation)};
  }
};

template <typename T>
Mat3<T> HatT(const Vec3<T>& v) {
  Mat3<T> m;
  m << T(0.0), -v.z(), v.y(), v.z(), T(0.0), -v.x(), -v.y(), v.x(), T(0.0);
  return m;
}

// Rotation vector of a unit quaternion (angle in [0, pi]); smooth at the identity.
template <typename T>
Vec3<T> LogRotation(const Eigen::Quaternion<T>& quaternion) {
  using std::atan2;
  using std::sqrt;
  Eigen::Quaternion<T> q = quaternion;
  if (q.w() < T(0.0)) q.coeffs() = -q.coeffs();
  const Vec3<T> v = q.vec();
  const T sin_half_squared = v.squaredNorm();
  if (sin_half_squared < T(1e-20)) {
    return (T(2.0) / q.w()) * v;  // first order; the next term is below 1e-20 relative
  }
  const T sin_half = sqrt(sin_half_squared);
  return (T(2.0) * atan2(sin_half, q.w()) / sin_half) * v;
}

// The matrix W with translation = W * upsilon in Sim3's exponential (same series and closed
// forms as geometry/sim3.cc, written for any scalar; theta enters through theta^2 near 0).
template <typename T>
Mat3<T> SimilarityW(const Vec3<T>& omega, const T& sigma) {
  using std::abs;
  using std::cos;
  using std::exp;
  using std::sin;
  using std::sqrt;
  constexpr double kSeriesRadius = 1e-2;
  constexpr double kEpsilon = 1e-8;
  const T theta2 = omega.squaredNorm();
  const Mat3<T> omega_hat = HatT(omega);
  T a(0.0), b(0.0), c(0.0);
  if (abs(sigma) < T(kSeriesRadius) && theta2 < T(kSeriesRadius * kSeriesRadius)) {
    const T theta4 = theta2 * theta2;
    T power(1.0);  // sigma^n / n!
    for (int n = 0; n < 9; ++n) {
      const double k = n;
      c += power / (k + 1.0);
      a += power * (1.0 / (k + 2.0) - theta2 / (6.0 * (k + 4.0)) + theta4 / (120.0 * (k + 6.0)));
      b += power *
           (1.0 / (2.0 * (k + 3.0)) - theta2 / (24.0 * (k + 5.0)) + theta4 / (720.0 * (k + 7.0)));
      power *= sigma / (k + 1.0);
    }
  } else {
    const T scale = exp(sigma);
    c = abs(sigma) < T(kEpsilon) ? T(1.0) + T(0.5) * sigma : (scale - T(1.0)) / sigma;
    if (theta2 < T(kEpsilon * kEpsilon)) {
      const T sigma2 = sigma * sigma;
      a = ((sigma - T(1.0)) * scale + T(1.0)) / sigma2;
      b = (scale * (T(0.5) * sigma2 - sigma + T(1.0)) - T(1.0)) / (sigma2 * sigma);
    } else {
      const T theta = sqrt(theta2);
      const T sin_theta = sin(theta);
      const T cos_theta = cos(theta);
      const T denominator = sigma * sigma + theta2;
      a = (scale * (sigma * sin_theta - theta * cos_theta) + theta) / (theta * denominator);
      b = (c - (scale * (sigma * cos_theta + theta * sin_theta) - sigma) / denominator) / theta2;
    }
  }
  return c * Mat3<T>::Identity() + a * omega_hat + b * omega_hat * omega_hat;
}

// Sim3 logarithm [upsilon; omega; sigma] as Sim3::Log.
template <typename T>
Eigen::Matrix<T, 7, 1> LogSimilarity(const SimilarityT<T>& s) {
  using std::log;
  Eigen::Matrix<T, 7, 1> tangent;
  const Vec3<T> omega = LogRotation(s.rotation);
  const T sigma = log(s.scale);
  tangent.template head<3>() = SimilarityW(omega, sigma).inverse() * s.translation;
  tangent.template segment<3>(3) = omega;
  tangent(6) = sigma;
  return tangent;
}

// Error of a relative measurement j_from_i between nodes i and j (each cam_from_world):
// Log(j_from_i_measured * S_i * S_j^-1), zero when the estimate agrees.
template <typename T>
Eigen::Matrix<T, 7, 1> RelativeSimilarityError(const SimilarityT<T>& j_from_i_measured,
                                               const SimilarityT<T>& i_from_world,
                                               const SimilarityT<T>& j_from_world) {
  return LogSimilarity(j_from_i_measured * i_from_world * j_from_world.Inverse());
}

// Error of an absolute prior on world_from_cam (rigid) given the node cam_from_world (Sim3):
// [camera centre minus measured centre, world frame, metres; Log(R_measured^-1 R), radians].
template <typename T>
Eigen::Matrix<T, 6, 1> PosePriorError(const Eigen::Quaternion<T>& measured_cam_to_world_rotation,
                                      const Vec3<T>& measured_centre,
                                      const SimilarityT<T>& cam_from_world) {
  const SimilarityT<T> world_from_cam = cam_from_world.Inverse();
  Eigen::Matrix<T, 6, 1> error;
  error.template head<3>() = world_from_cam.translation - measured_centre;
  error.template tail<3>() = LogRotation(
      Eigen::Quaternion<T>(measured_cam_to_world_rotation.conjugate() * world_from_cam.rotation));
  return error;
}

}  // namespace pose_graph_internal
}  // namespace arucoslam
