#include "arucoslam/eval/pose_error.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

double ErrorOf(const Rigid3& error_pose, PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation:
      return error_pose.translation.norm();
    case PoseRelation::kRotationAngleDeg:
      return RotationAngle(error_pose.rotation) * 180.0 / std::numbers::pi;
    case PoseRelation::kRotationAngleRad:
      return RotationAngle(error_pose.rotation);
    case PoseRelation::kFullTransformation:
      return (error_pose.ToMatrix() - Eigen::Matrix4d::Identity()).norm();
  }
  return 0.0;
}

// Consecutive pairs where an accumulated quantity (path length or time) reaches `delta`
// since the previous chosen index; `step(i)` is the increment from i - 1 to i.
template <typename Step>
IndexPairs ConsecutiveByAccumulation(std::size_t size, double delta, Step step) {
  std::vector<std::size_t> ids;
  double accumulated = 0.0;
  for (std::size_t i = 0; i < size; ++i) {
    if (i > 0) accumulated += step(i);
    if (accumulated >= delta) {
      ids.push_back(i);
      accumulated = 0.0;
    }
  }
  IndexPairs pairs;
  for (std::size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return pairs;
}

// For each i, the j > i whose `cumulative[j] - cumulative[i]` is closest to delta (the first
// on a tie), kept when within `tolerance`. `cumulative` does not decrease.
IndexPairs AllPairsByAccumulation(const std::vector<double>& cumulative, double delta,
                                  double tolerance) {
  IndexPairs pairs;
  for (std::size_t i = 0; i + 1 < cumulative.size(); ++i) {
    const double target = cumulative[i] + delta;
    auto it =
        std::lower_bound(cumulative.begin() + static_cast<long>(i) + 1, cumulative.end(), target);
    std::size_t best = static_cast<std::size_t>(it - cumulative.begin());
    if (best == cumulative.size()) --best;
    if (best > i + 1) {
      const double below = cumulative[best - 1] - cumulative[i] - delta;
      const double at = cumulative[best] - cumulative[i] - delta;
      if (it == cumulative.end() || std::abs(below) <= std::abs(at)) {
        // First index of the run of equal values below.
        best =
            static_cast<std::size_t>(std::lower_bound(cumulative.begin() + static_cast<long>(i) + 1,
                                                      cumulative.end(), cumulative[best - 1]) -
                                     cumulative.begin());
      }
    }
    if (std::abs(cumulative[best] - cumulative[i] - delta) <= tolerance) {
      pairs.emplace_back(i, best);
    }
  }
  return pairs;
}

}  // namespace

std::string PoseRelationName(PoseRelation relation) {
  switch (relation) {
    case PoseRelation::kTranslation:
      return "translation part";
    case PoseRelation::kRotationAngleDeg:
      return "rotation angle in degrees";
    case PoseRelation::kRotationAngleRad:
      return "rotation angle in radians";
    case PoseRelation::kFullTransformation:
      return "full transformation";
  }
  return "";
}

std::string DeltaUnitName(DeltaUnit unit) {
  switch (unit) {
    case DeltaUnit::kFrames:
      return "frames";
    case DeltaUnit::kSeconds:
      return "s";
    case DeltaUnit::kMeters:
      return "m";
  }
  return "";
}

bool RelativeErrorOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Rule(delta > 0.0 && std::isfinite(delta), "delta", delta, "finite and > 0");
  check.Rule(unit != DeltaUnit::kFrames || delta == std::floor(delta), "delta", delta,
             "a whole number of frames");
  check.AtLeast("relative_tolerance", relative_tolerance, 0.0);
  return check.ok();
}

std::vector<double> AbsolutePoseErrors(const Trajectory& gt, const Trajectory& est,
                                       PoseRelation relation) {
  if (gt.size() != est.size()) throw std::invalid_argument("AbsolutePoseErrors: size mismatch");
  std::vector<double> errors;
  errors.reserve(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    if (relation == PoseRelation::kTranslation) {
      errors.push_back((est.poses[i].translation - gt.poses[i].translation).norm());
    } else {
      errors.push_back(ErrorOf(est.poses[i].Inverse() * gt.poses[i], relation));
    }
  }
  return errors;
}

IndexPairs RelativeIndexPairs(const Trajectory& est, const RelativeErrorOptions& options) {
  if (!options.Check()) throw std::invalid_argument("RelativeErrorOptions: invalid");
  const std::size_t n = est.size();
  IndexPairs pairs;
  if (options.unit == DeltaUnit::kFrames) {
    const std::size_t step = static_cast<std::size_t>(options.delta);
    if (options.all_pairs) {
      for (std::size_t i = 0; i + step < n; ++i) pairs.emplace_back(i, i + step);
    } else {
      for (std::size_t i = 0; i + step < n; i += step) pairs.emplace_back(i, i + step);
    }
    return pairs;
  }
  const bool meters = options.unit == DeltaUnit::kMeters;
  const auto step = [&](std::size_t i) {
    return meters ? (est.poses[i].translation - est.poses[i - 1].translation).norm()
                  : est.timestamps[i] - est.timestamps[i - 1];
  };
  if (!options.all_pairs) return ConsecutiveByAccumulation(n, options.delta, step);
  std::vector<double> cumulative(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) cumulative[i] = cumulative[i - 1] + step(i);
  return AllPairsByAccumulation(cumulative, options.delta,
                                options.delta * options.relative_tolerance);
}

std::vector<double> RelativePoseErrors(const Trajectory& gt, const Trajectory& est,
                                       const IndexPairs& pairs, PoseRelation relation) {
  if (gt.size() != est.size()) throw std::invalid_argument("RelativePoseErrors: size mismatch");
  std::vector<double> errors;
  errors.reserve(pairs.size());
  for (const auto& [i, j] : pairs) {
    if (relation == PoseRelation::kTranslation) {
      // Rotation matrices as given, inverse by transpose (evo's arithmetic on KITTI files).
      const Eigen::Matrix3d gt_i = gt.RotationMatrix(i);
      const Eigen::Matrix3d est_i = est.RotationMatrix(i);
      const Eigen::Vector3d gt_step =
          gt_i.transpose() * (gt.poses[j].translation - gt.poses[i].translation);
      const Eigen::Vector3d est_step =
          est_i.transpose() * (est.poses[j].translation - est.poses[i].translation);
      const Eigen::Matrix3d gt_turn = gt_i.transpose() * gt.RotationMatrix(j);
      errors.push_back((gt_turn.transpose() * (est_step - gt_step)).norm());
      continue;
    }
    const Rigid3 gt_motion = gt.poses[i].Inverse() * gt.poses[j];
    const Rigid3 est_motion = est.poses[i].Inverse() * est.poses[j];
    errors.push_back(ErrorOf(gt_motion.Inverse() * est_motion, relation));
  }
  return errors;
}

}  // namespace arucoslam
