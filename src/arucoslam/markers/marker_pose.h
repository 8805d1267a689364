// Per-marker pose from one detection: IPPE for squares gives the two cam_from_marker
// solutions of a planar square; both are kept with their reprojection errors and a flag.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct MarkerPoseOptions {
  // A view is ambiguous when the second IPPE solution explains the corners almost as well
  // as the first: best_error / second_error > ambiguity_ratio (errors are RMS pixels), or
  // second_error < min_distinct_error_px (both within ordinary corner noise). 0.6 follows
  // the ratio used for planar-target ambiguity in practice; 1 px is several times the
  // sub-pixel corner noise seen on real images.
  double ambiguity_ratio = 0.6;        // in (0, 1]
  double min_distinct_error_px = 1.0;  // pixels, >= 0

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.InRange("ambiguity_ratio", ambiguity_ratio, 0.0, 1.0, Interval::kOpenClosed);
    check.AtLeast("min_distinct_error_px", min_distinct_error_px, 0.0);
    return check.ok();
  }
};

struct MarkerPoseSolution {
  Rigid3 cam_from_marker;
  double reprojection_rms_px = 0.0;  // RMS over the 4 corners, pixels
};

struct MarkerPose {
  int id = -1;
  // solutions[0] has the smaller error; num_solutions is 1 or 2.
  std::array<MarkerPoseSolution, 2> solutions;
  int num_solutions = 0;
  double error_ratio = 0.0;  // best / second error (0 with one solution)
  bool ambiguous = false;

  const MarkerPoseSolution& Best() const { return solutions[0]; }
};

// Pose of a square marker of side `size` (metres) from its 4 detected corners. Corners are
// undistorted through CameraModel::Unproject and solved in normalised coordinates.
// nullopt when IPPE fails or no solution puts the marker in front of the camera.
std::optional<MarkerPose> EstimateMarkerPose(const MarkerDetection& detection, double size,
                                             const CameraModel& camera,
                                             const MarkerPoseOptions& options = {});

// RMS pixel distance between `pixels` and the projections of `points_in_marker`.
double MarkerReprojectionRms(const CameraModel& camera, const Rigid3& cam_from_marker,
                             const std::array<Eigen::Vector3d, 4>& points_in_marker,
                             const std::array<Eigen::Vector2d, 4>& pixels);

// Corners of a square of side `size` in its marker frame, OpenCV order.
std::array<Eigen::Vector3d, 4> SquareCorners(double size);

// Rigid3 from OpenCV's rvec / tvec (3x1 double) and back.
Rigid3 RigidFromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec);
void RvecTvecFromRigid(const Rigid3& transform, cv::Mat& rvec, cv::Mat& tvec);

}  // namespace arucoslam
