#include "arucoslam/markers/camera_locator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <set>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool CameraLocatorOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("inlier_threshold_px", inlier_threshold_px, 0.0);
  check.AtLeast("ransac_iterations", ransac_iterations, 1);
  check.InRange("ransac_confidence", ransac_confidence, 0.0, 1.0, Interval::kOpen);
  check.AtLeast("min_inlier_corners", min_inlier_corners, 4);
  check.AtLeast("refine_max_iterations", refine_max_iterations, 0);
  check.InRange("max_view_angle_deg", max_view_angle_deg, 0.0, 90.0, Interval::kOpenClosed);
  check.Nested("marker_pose", marker_pose);
  return check.ok();
}

namespace {

struct Correspondences {
  std::vector<cv::Point3d> in_world;
  std::vector<cv::Point2d> normalised;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<int> marker_ids;             // per corner
  std::vector<Rigid3> world_from_markers;  // per corner, its marker's pose
  double min_view_cosine = 0.0;            // cos(max_view_angle_deg)
};

struct Score {
  int inliers = 0;
  double cost = std::numeric_limits<double>::infinity();  // truncated squared error (MSAC)
  bool BetterThan(const Score& other) const {
    return inliers != other.inliers ? inliers > other.inliers : cost < other.cost;
  }
};

// Pixel error of each correspondence under world_from_cam: infinite behind the camera, and
// for the corners of a marker the camera would see from behind or more edge-on than
// max_view_angle_deg (it cannot have been detected there).
std::vector<double> PixelErrors(const Correspondences& c, const CameraModel& camera,
                                const Rigid3& world_from_cam) {
  const Rigid3 cam_from_world = world_from_cam.Inverse();
  std::vector<double> errors(c.pixels.size(), std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < c.pixels.size(); ++i) {
    if (!SeesPrintedSide(c.world_from_markers[i], world_from_cam.translation, c.min_view_cosine)) {
      continue;
    }
    const Eigen::Vector3d p(c.in_world[i].x, c.in_world[i].y, c.in_world[i].z);
    const auto projected = camera.Project(cam_from_world * p);
    if (projected) errors[i] = (*projected - c.pixels[i]).norm();
  }
  return errors;
}

Score ScorePose(const Correspondences& c, const CameraModel& camera, const Rigid3& world_from_cam,
                double threshold) {
  Score score;
  score.cost = 0.0;
  for (const double e : PixelErrors(c, camera, world_from_cam)) {
    if (e < threshold) ++score.inliers;
    score.cost += std::min(e * e, threshold * threshold);
  }
  return score;
}

// Levenberg-Marquardt on the inliers, in normalised coordinates.
Rigid3 Refine(const Correspondences& c, const CameraModel& camera, const Rigid3& world_from_cam,
              double threshold, int iterations) {
  if (iterations <= 0) return world_from_cam;
  const std::vector<double> errors = PixelErrors(c, camera, world_from_cam);
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  for (size_t i = 0; i < errors.size(); ++i) {
    if (errors[i] < threshold) {
      object.push_back(c.in_world[i]);
      image.push_back(c.normalised[i]);
    }
  }
  if (object.size() < 4) return world_from_cam;
  cv::Mat rvec, tvec;
  RvecTvecFromRigid(world_from_cam.Inverse(), rvec, tvec);
  cv::solvePnPRefineLM(
      object, image, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvec, tvec,
      cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, iterations, 1e-12));
  return RigidFromRvecTvec(rvec, tvec).Inverse();
}

// Correspondences of the known markers' corners, and IPPE hypotheses from each marker.
void CollectKnownCorners(const std::vector<MarkerDetection>& detections, const MarkerMap& map,
                         const CameraModel& camera, const MarkerPoseOptions& pose_options,
                         Correspondences& c, std::vector<Rigid3>& hypotheses,
                         std::vector<MarkerPose>& marker_poses, std::set<int>& unknown) {
  for (const MarkerDetection& detection : detections) {
    const MarkerInfo* info = map.Find(detection.id);
    if (info == nullptr) {
      unknown.insert(detection.id);
      continue;
    }
    const std::array<Eigen::Vector3d, 4> in_world = info->CornersInWorld();
    for (int k = 0; k < 4; ++k) {
      c.world_from_markers.push_back(info->world_from_marker);
      const Eigen::Vector2d xy = camera.Unproject(detection.corners[k]);
      c.in_world.emplace_back(in_world[k].x(), in_world[k].y(), in_world[k].z());
      c.normalised.emplace_back(xy.x(), xy.y());
      c.pixels.push_back(detection.corners[k]);
      c.marker_ids.push_back(detection.id);
    }
    const std::optional<MarkerPose> pose =
        EstimateMarkerPose(detection, info->size, camera, pose_options);
    if (!pose) continue;
    marker_poses.push_back(*pose);
    for (int s = 0; s < pose->num_solutions; ++s) {
      hypotheses.push_back(info->world_from_marker * pose->solutions[s].cam_from_marker.Inverse());
    }
  }
}

// RANSAC PnP (SQPnP) over all corners, in normalised coordinates.
std::optional<Rigid3> RansacPnp(const Correspondences& c, const CameraModel& camera,
                                const CameraLocatorOptions& options) {
  const double focal = std::max(camera.fx, camera.fy);
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  const bool ok = cv::solvePnPRansac(c.in_world, c.normalised, cv::Mat::eye(3, 3, CV_64F),
                                     cv::Mat(), rvec, tvec, false, options.ransac_iterations,
                                     static_cast<float>(options.inlier_threshold_px / focal),
                                     options.ransac_confidence, inliers, cv::SOLVEPNP_SQPNP);
  if (!ok) return std::nullopt;
  return RigidFromRvecTvec(rvec, tvec).Inverse();
}

// The best hypothesis by inliers then truncated cost, refined by LM while that helps.
std::pair<Rigid3, Score> SelectAndRefine(const Correspondences& c, const CameraModel& camera,
                                         const std::vector<Rigid3>& hypotheses,
                                         const CameraLocatorOptions& options) {
  const double threshold = options.inlier_threshold_px;
  Rigid3 best = hypotheses.front();
  Score best_score = ScorePose(c, camera, best, threshold);
  for (const Rigid3& h : hypotheses) {
    const Score score = ScorePose(c, camera, h, threshold);
    if (score.BetterThan(best_score)) {
      best = h;
      best_score = score;
    }
  }
  for (int round = 0; round < 2; ++round) {
    const Rigid3 refined = Refine(c, camera, best, threshold, options.refine_max_iterations);
    const Score score = ScorePose(c, camera, refined, threshold);
    if (!(score.inliers >= best_score.inliers && score.cost <= best_score.cost + 1e-12)) break;
    best = refined;
    best_score = score;
  }
  return {best, best_score};
}

// One marker used: its IPPE ambiguity, and the other IPPE solution as the alternative,
// refined by LM when the refinement stays in that solution's basin (away from the best).
void FillSingleMarkerAmbiguity(const std::vector<MarkerPose>& marker_poses, const MarkerMap& map,
                               const Correspondences& c, const CameraModel& camera,
                               const CameraLocatorOptions& options, CameraLocation& result) {
  const auto distance = [&result](const Rigid3& x) {
    return RotationAngle(x.rotation.inverse() * result.world_from_cam.rotation);
  };
  for (const MarkerPose& pose : marker_poses) {
    if (pose.id != result.marker_ids.front()) continue;
    result.quality.ambiguous = pose.ambiguous;
    result.quality.error_ratio = pose.error_ratio;
    if (pose.num_solutions < 2) continue;
    const MarkerInfo* info = map.Find(pose.id);
    const Rigid3 a = info->world_from_marker * pose.solutions[0].cam_from_marker.Inverse();
    const Rigid3 b = info->world_from_marker * pose.solutions[1].cam_from_marker.Inverse();
    const Rigid3 alternative = distance(a) > distance(b) ? a : b;
    const double threshold = options.inlier_threshold_px;
    const Rigid3 refined = Refine(c, camera, alternative, threshold, options.refine_max_iterations);
    const Score before = ScorePose(c, camera, alternative, threshold);
    const Score after = ScorePose(c, camera, refined, threshold);
    const bool keeps_basin = distance(refined) > 0.5 * distance(alternative);
    result.alternative_world_from_cam =
        keeps_basin && after.inliers >= before.inliers && after.cost <= before.cost ? refined
                                                                                    : alternative;
    const std::vector<double> errors = PixelErrors(c, camera, *result.alternative_world_from_cam);
    double sum = 0.0;
    int count = 0;
    for (size_t i = 0; i < errors.size(); ++i) {
      if (c.marker_ids[i] != pose.id) continue;
      sum += errors[i] * errors[i];
      ++count;
    }
    result.quality.alternative_rms_px = std::sqrt(sum / count);
  }
}

// Rotation of `pose` from a predicted orientation in units of the rotation gate.
double RotationGateUnits(const Rigid3& pose, const Eigen::Quaterniond& predicted,
                         const AmbiguityPriorGates& gates) {
  return RotationAngle(pose.rotation.inverse() * predicted) * 180.0 / M_PI / gates.max_rotation_deg;
}

// Distance of `pose` from `predicted` in units of its gate (the larger of rotation and
// position).
double GateUnits(const Rigid3& pose, const Rigid3& predicted, const AmbiguityPriorGates& gates) {
  const double position_m = (pose.translation - predicted.translation).norm();
  return std::max(RotationGateUnits(pose, predicted.rotation, gates),
                  position_m / gates.max_position_m);
}

// The solution of an ambiguous location within one gate unit (`units(pose)`) of a
// prediction while the other lies beyond min_disagreement units.
template <typename Units>
AmbiguityChoice ChooseWithinGate(const CameraLocation& location, const AmbiguityPriorGates& gates,
                                 const Units& units) {
  if (!location.found || !location.alternative_world_from_cam || !gates.Check()) {
    return AmbiguityChoice::kNone;
  }
  const double best = units(location.world_from_cam);
  const double other = units(*location.alternative_world_from_cam);
  if (best <= 1.0 && other >= gates.min_disagreement) return AmbiguityChoice::kBest;
  if (other <= 1.0 && best >= gates.min_disagreement) return AmbiguityChoice::kAlternative;
  return AmbiguityChoice::kNone;
}

}  // namespace

CameraLocation LocateCamera(const std::vector<MarkerDetection>& detections, const MarkerMap& map,
                            const CameraModel& camera, const CameraLocatorOptions& options) {
  CameraLocation result;
  if (!options.Check()) {
    result.failure = "invalid CameraLocatorOptions";
    return result;
  }
  Correspondences c;
  c.min_view_cosine = std::cos(options.max_view_angle_deg * M_PI / 180.0);
  std::vector<Rigid3> hypotheses;
  std::vector<MarkerPose> marker_poses;
  std::set<int> unknown;
  CollectKnownCorners(detections, map, camera, options.marker_pose, c, hypotheses, marker_poses,
                      unknown);
  result.unknown_marker_ids.assign(unknown.begin(), unknown.end());
  result.quality.num_corners = static_cast<int>(c.pixels.size());
  if (c.pixels.empty()) {
    result.failure = "no known marker detected";
    return result;
  }
  if (c.pixels.size() >= 8) {
    if (const std::optional<Rigid3> pose = RansacPnp(c, camera, options)) {
      hypotheses.push_back(*pose);
    }
  }
  if (hypotheses.empty()) {
    result.failure = "no pose hypothesis from the detected markers";
    return result;
  }
  const auto [best, score] = SelectAndRefine(c, camera, hypotheses, options);
  if (score.inliers < options.min_inlier_corners) {
    result.failure = "too few inlier corners (" + std::to_string(score.inliers) + ")";
    return result;
  }
  const std::vector<double> errors = PixelErrors(c, camera, best);
  std::set<int> used;
  double sum = 0.0;
  for (size_t i = 0; i < errors.size(); ++i) {
    if (errors[i] >= options.inlier_threshold_px) continue;
    sum += errors[i] * errors[i];
    used.insert(c.marker_ids[i]);
  }
  result.found = true;
  result.world_from_cam = best;
  result.marker_ids.assign(used.begin(), used.end());
  result.quality.num_inlier_corners = score.inliers;
  result.quality.num_markers = static_cast<int>(used.size());
  result.quality.reprojection_rms_px = std::sqrt(sum / score.inliers);
  if (used.size() == 1) FillSingleMarkerAmbiguity(marker_poses, map, c, camera, options, result);
  return result;
}

AmbiguityChoice ResolveAmbiguity(const CameraLocation& location,
                                 const Rigid3& predicted_world_from_cam,
                                 const AmbiguityPriorGates& gates) {
  return ChooseWithinGate(location, gates, [&](const Rigid3& pose) {
    return GateUnits(pose, predicted_world_from_cam, gates);
  });
}

AmbiguityChoice ResolveAmbiguityByRotation(const CameraLocation& location,
                                           const Eigen::Quaterniond& predicted_world_from_cam,
                                           const AmbiguityPriorGates& gates) {
  return ChooseWithinGate(location, gates, [&](const Rigid3& pose) {
    return RotationGateUnits(pose, predicted_world_from_cam, gates);
  });
}

std::optional<Rigid3> ChosenPose(const CameraLocation& location, AmbiguityChoice choice) {
  switch (choice) {
    case AmbiguityChoice::kBest:
      return location.world_from_cam;
    case AmbiguityChoice::kAlternative:
      return location.alternative_world_from_cam;
    case AmbiguityChoice::kNone:
      break;
  }
  return std::nullopt;
}

}  // namespace arucoslam
