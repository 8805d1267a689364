#include "arucoslam/geometry/umeyama.h"

#include <Eigen/SVD>

namespace arucoslam {

std::optional<Sim3> UmeyamaAlignment(const std::vector<Eigen::Vector3d>& source,
                                     const std::vector<Eigen::Vector3d>& target,
                                     AlignmentKind kind) {
  if (source.size() != target.size() || source.size() < 3) return std::nullopt;
  const double count = static_cast<double>(source.size());
  Eigen::Vector3d source_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) {
    source_mean += source[i];
    target_mean += target[i];
  }
  source_mean /= count;
  target_mean /= count;

  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double source_variance = 0.0;
  for (std::size_t i = 0; i < source.size(); ++i) {
    const Eigen::Vector3d s = source[i] - source_mean;
    covariance += (target[i] - target_mean) * s.transpose();
    source_variance += s.squaredNorm();
  }
  covariance /= count;
  source_variance /= count;
  if (source_variance < 1e-18) return std::nullopt;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d sign = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) sign(2, 2) = -1.0;
  const Eigen::Matrix3d rotation = svd.matrixU() * sign * svd.matrixV().transpose();
  double scale = 1.0;
  if (kind == AlignmentKind::kSimilarity) {
    scale = (svd.singularValues().asDiagonal() * sign).trace() / source_variance;
    // A target collapsed to one point gives scale 0: no similarity maps onto it.
    if (!(scale > 0.0)) return std::nullopt;
  }
  const Eigen::Vector3d translation = target_mean - scale * rotation * source_mean;
  return Sim3(scale, Eigen::Quaterniond(rotation), translation);
}

}  // namespace arucoslam
