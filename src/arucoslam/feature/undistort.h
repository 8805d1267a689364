// UndistortFeatures: fills OrbFeatures::undistorted with the normalised, distortion-free
// coordinates of every keypoint (CameraModel::Unproject), as two-view geometry and BA use them.
#pragma once

#include "arucoslam/feature/keypoints.h"
#include "arucoslam/geometry/camera.h"

namespace arucoslam {

void UndistortFeatures(const CameraModel& camera, OrbFeatures* features);

}  // namespace arucoslam
