#include "arucoslam/eval/alignment.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "arucoslam/geometry/umeyama.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

std::optional<AlignmentMode> ParseAlignmentMode(const std::string& name) {
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "none") return AlignmentMode::kNone;
  if (lower == "se3") return AlignmentMode::kSe3;
  if (lower == "sim3") return AlignmentMode::kSim3;
  return std::nullopt;
}

std::string AlignmentModeName(AlignmentMode mode) {
  switch (mode) {
    case AlignmentMode::kSe3:
      return "SE3";
    case AlignmentMode::kSim3:
      return "Sim3";
    case AlignmentMode::kNone:
      break;
  }
  return "none";
}

bool AlignmentOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("first_poses", first_poses, 0);
  if (window_start && window_end) {
    // Written as before (a NaN bound passes): only an end before the start is refused.
    check.Rule(!(*window_end < *window_start), "window_end", *window_end, ">= window_start");
  }
  return check.ok();
}

std::optional<AlignmentResult> ComputeAlignment(const AssociatedTrajectories& pairs,
                                                const AlignmentOptions& options) {
  if (!options.Check()) throw std::invalid_argument("AlignmentOptions: invalid");
  AlignmentResult result;
  result.mode = options.mode;
  if (options.mode == AlignmentMode::kNone) {
    result.num_fitted = 0;
    return result;
  }
  std::vector<Eigen::Vector3d> source;
  std::vector<Eigen::Vector3d> target;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (options.first_poses > 0 && i >= static_cast<std::size_t>(options.first_poses)) break;
    const double t = pairs.gt.timestamps[i];
    if (options.window_start && t < *options.window_start) continue;
    if (options.window_end && t > *options.window_end) continue;
    source.push_back(pairs.est.poses[i].translation);
    target.push_back(pairs.gt.poses[i].translation);
  }
  const AlignmentKind kind =
      options.mode == AlignmentMode::kSim3 ? AlignmentKind::kSimilarity : AlignmentKind::kRigid;
  const std::optional<Sim3> fit = UmeyamaAlignment(source, target, kind);
  if (!fit) return std::nullopt;
  result.gt_from_est = *fit;
  result.num_fitted = source.size();
  return result;
}

Trajectory ApplyAlignment(const Sim3& gt_from_est, const Trajectory& est) {
  Trajectory aligned;
  aligned.timestamps = est.timestamps;
  aligned.poses.reserve(est.size());
  for (const Rigid3& pose : est.poses) aligned.poses.push_back(gt_from_est.TransformPose(pose));
  const Eigen::Matrix3d rotation = gt_from_est.rotation.toRotationMatrix();
  for (const Eigen::Matrix3d& raw : est.raw_rotations) {
    aligned.raw_rotations.push_back(rotation * raw);
  }
  return aligned;
}

}  // namespace arucoslam
