// Information matrices of camera pose priors from standard deviations: what a prior weighs in a
// pose graph or an adjustment, ordered [centre (3); rotation (3)] as KeyframePosePrior's.
#pragma once

#include <Eigen/Core>

namespace arucoslam {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Diagonal information of a pose known to within `position_sigma_m` (metres, each axis of the
// camera centre) and `rotation_sigma_rad` (radians, each axis of the rotation). Both sigmas > 0.
inline Matrix6d IsotropicPoseInformation(double position_sigma_m, double rotation_sigma_rad) {
  Matrix6d information = Matrix6d::Zero();
  information.topLeftCorner<3, 3>().diagonal().setConstant(1.0 /
                                                           (position_sigma_m * position_sigma_m));
  information.bottomRightCorner<3, 3>().diagonal().setConstant(
      1.0 / (rotation_sigma_rad * rotation_sigma_rad));
  return information;
}

// Standard deviation, metres, of the camera centre along its least certain direction: the
// square root of the largest eigenvalue of the centre block of information^-1. A diagonal
// `information` gives 1 / sqrt of its smallest centre entry, exactly.
double LeastCertainPositionSigma(const Matrix6d& information);

// The information of a prior whose covariance is that of `information` plus a diagonal floor
// (`floor_variances`, all > 0): (information^-1 + floor)^-1, computed without inverting a
// singular `information`, so a prior is never firmer than the floor allows.
Matrix6d WithCovarianceFloor(const Matrix6d& information,
                             const Eigen::Matrix<double, 6, 1>& floor_variances);

}  // namespace arucoslam
