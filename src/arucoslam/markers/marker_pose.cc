#include "arucoslam/markers/marker_pose.h"

#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <vector>

namespace arucoslam {

std::array<Eigen::Vector3d, 4> SquareCorners(double size) {
  const double half = 0.5 * size;
  return {Eigen::Vector3d(-half, half, 0.0), Eigen::Vector3d(half, half, 0.0),
          Eigen::Vector3d(half, -half, 0.0), Eigen::Vector3d(-half, -half, 0.0)};
}

Rigid3 RigidFromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat rotation_cv;
  cv::Rodrigues(rvec, rotation_cv);
  Eigen::Matrix3d rotation;
  cv::cv2eigen(rotation_cv, rotation);
  Eigen::Vector3d translation;
  cv::Mat tvec64;
  tvec.convertTo(tvec64, CV_64F);
  translation << tvec64.at<double>(0), tvec64.at<double>(1), tvec64.at<double>(2);
  return Rigid3(rotation, translation);
}

void RvecTvecFromRigid(const Rigid3& transform, cv::Mat& rvec, cv::Mat& tvec) {
  cv::Mat rotation_cv;
  cv::eigen2cv(Eigen::Matrix3d(transform.RotationMatrix()), rotation_cv);
  cv::Rodrigues(rotation_cv, rvec);
  tvec = (cv::Mat_<double>(3, 1) << transform.translation.x(), transform.translation.y(),
          transform.translation.z());
}

double MarkerReprojectionRms(const CameraModel& camera, const Rigid3& cam_from_marker,
                             const std::array<Eigen::Vector3d, 4>& points_in_marker,
                             const std::array<Eigen::Vector2d, 4>& pixels) {
  double sum = 0.0;
  for (int i = 0; i < 4; ++i) {
    const std::optional<Eigen::Vector2d> projected =
        camera.Project(cam_from_marker * points_in_marker[i]);
    if (!projected) return std::numeric_limits<double>::infinity();
    sum += (*projected - pixels[i]).squaredNorm();
  }
  return std::sqrt(sum / 4.0);
}

std::optional<MarkerPose> EstimateMarkerPose(const MarkerDetection& detection, double size,
                                             const CameraModel& camera,
                                             const MarkerPoseOptions& options) {
  if (!(size > 0.0) || !options.Check()) return std::nullopt;
  const std::array<Eigen::Vector3d, 4> corners = SquareCorners(size);
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> normalised;
  for (int i = 0; i < 4; ++i) {
    object.emplace_back(corners[i].x(), corners[i].y(), 0.0);
    const Eigen::Vector2d xy = camera.Unproject(detection.corners[i]);
    if (!xy.allFinite()) return std::nullopt;
    normalised.emplace_back(xy.x(), xy.y());
  }
  std::vector<cv::Mat> rvecs, tvecs;
  int count = 0;
  try {
    count = cv::solvePnPGeneric(object, normalised, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvecs,
                                tvecs, false, cv::SOLVEPNP_IPPE_SQUARE);
  } catch (const cv::Exception&) {
    return std::nullopt;  // degenerate corners (e.g. collinear)
  }
  MarkerPose pose;
  pose.id = detection.id;
  for (int i = 0; i < count && pose.num_solutions < 2; ++i) {
    MarkerPoseSolution solution;
    solution.cam_from_marker = RigidFromRvecTvec(rvecs[i], tvecs[i]);
    if (solution.cam_from_marker.translation.z() <= 0.0) continue;
    solution.reprojection_rms_px =
        MarkerReprojectionRms(camera, solution.cam_from_marker, corners, detection.corners);
    if (!std::isfinite(solution.reprojection_rms_px)) continue;
    pose.solutions[pose.num_solutions++] = solution;
  }
  if (pose.num_solutions == 0) return std::nullopt;
  if (pose.num_solutions == 2) {
    if (pose.solutions[1].reprojection_rms_px < pose.solutions[0].reprojection_rms_px) {
      std::swap(pose.solutions[0], pose.solutions[1]);
    }
    const double best = pose.solutions[0].reprojection_rms_px;
    const double second = pose.solutions[1].reprojection_rms_px;
    pose.error_ratio = second > 0.0 ? best / second : 1.0;
    pose.ambiguous =
        pose.error_ratio > options.ambiguity_ratio || second < options.min_distinct_error_px;
  }
  return pose;
}

}  // namespace arucoslam
