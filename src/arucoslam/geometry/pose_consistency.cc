#include "arucoslam/geometry/pose_consistency.h"

#include <algorithm>

namespace arucoslam {

std::vector<StampedPose> DropPosesOffTheirKeyframes(const std::vector<StampedPose>& frames,
                                                    std::vector<StampedPose> keyframes,
                                                    const PoseConsistencyOptions& options,
                                                    int* num_dropped) {
  std::sort(keyframes.begin(), keyframes.end(), [](const StampedPose& a, const StampedPose& b) {
    return a.timestamp_s < b.timestamp_s;
  });
  std::vector<StampedPose> kept;
  kept.reserve(frames.size());
  int dropped = 0;
  for (const StampedPose& frame : frames) {
    const auto after = std::lower_bound(
        keyframes.begin(), keyframes.end(), frame.timestamp_s,
        [](const StampedPose& keyframe, double t) { return keyframe.timestamp_s < t; });
    if (after == keyframes.begin() || after == keyframes.end()) {
      kept.push_back(frame);
      continue;
    }
    const StampedPose& before = *(after - 1);
    const double gap_s = after->timestamp_s - before.timestamp_s;
    if (gap_s > options.max_keyframe_gap_s || gap_s <= 0.0) {
      kept.push_back(frame);
      continue;
    }
    const Eigen::Vector3d& a = before.world_from_cam.translation;
    const Eigen::Vector3d& b = after->world_from_cam.translation;
    const double w = (frame.timestamp_s - before.timestamp_s) / gap_s;
    const double offset = (frame.world_from_cam.translation - (a + w * (b - a))).norm();
    if (offset > std::max(options.max_offset_m, (b - a).norm())) {
      ++dropped;
      continue;
    }
    kept.push_back(frame);
  }
  if (num_dropped != nullptr) *num_dropped = dropped;
  return kept;
}

}  // namespace arucoslam
