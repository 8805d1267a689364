#include "arucoslam/feature/undistort.h"

namespace arucoslam {

void UndistortFeatures(const CameraModel& camera, OrbFeatures* features) {
  features->undistorted.clear();
  features->undistorted.reserve(features->keypoints.size());
  for (const cv::KeyPoint& kp : features->keypoints) {
    features->undistorted.push_back(camera.Unproject(Eigen::Vector2d(kp.pt.x, kp.pt.y)));
  }
}

}  // namespace arucoslam
