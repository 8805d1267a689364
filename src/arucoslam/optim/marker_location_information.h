// MarkerLocationInformation: how firmly the corners of known markers fix a camera's pose, as
// the information of a pose prior over PosePriorError's [centre; rotation] error.
#pragma once

#include <vector>

#include "arucoslam/geometry/pose_information.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/optim/marker_pose_optimizer.h"
#include "arucoslam/optim/reprojection_error.h"

namespace arucoslam {

// Gauss-Newton information (sum of J^T J / sigma_px^2) of the corners of `markers` (undistorted
// pixels, each with its sigma_px) at `world_from_cam`, over [camera centre in the world, metres;
// rotation R_measured^-1 * R in the camera frame, radians]. A marker with a corner behind the
// camera adds nothing; the result is singular when too little is seen to fix a pose.
Matrix6d MarkerLocationInformation(const Rigid3& world_from_cam,
                                   const std::vector<MarkerPoseObservation>& markers,
                                   const PinholeIntrinsics& intrinsics);

}  // namespace arucoslam
