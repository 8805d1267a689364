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

}  // namespace arucoslam
