#include "arucoslam/slam/covisible_marker_vote.h"

#include <algorithm>
#include <optional>

#include "arucoslam/markers/marker_pose.h"

namespace arucoslam {

int CovisibleMarkerVote::Agreeing(const AmbiguousFrame& a, const Rigid3& world_from_a,
                                  const AmbiguousFrame& b, const Rigid3& world_from_b) const {
  int agreeing = 0;
  auto it = b.centres.begin();
  for (const Centre& centre : a.centres) {
    it = std::lower_bound(it, b.centres.end(), centre.id,
                          [](const Centre& c, int id) { return c.id < id; });
    if (it == b.centres.end()) break;
    if (it->id != centre.id) continue;
    const double distance = std::max(centre.in_cam.norm(), it->in_cam.norm());
    const double tolerance =
        options_.max_disagreement_m + options_.max_disagreement_fraction * distance;
    if ((world_from_a * centre.in_cam - world_from_b * it->in_cam).norm() <= tolerance) {
      ++agreeing;
    }
  }
  return agreeing;
}

AmbiguityChoice CovisibleMarkerVote::Add(const CameraLocation& location,
                                         const std::vector<MarkerDetection>& unknown,
                                         double unknown_size, const CameraModel& camera) {
  if (!location.found || !location.alternative_world_from_cam || !(unknown_size > 0.0)) {
    return AmbiguityChoice::kNone;
  }
  AmbiguousFrame frame;
  frame.world_from_cam[0] = location.world_from_cam;
  frame.world_from_cam[1] = *location.alternative_world_from_cam;
  for (const MarkerDetection& detection : unknown) {
    // The centre's position in the camera hardly depends on which IPPE solution is right.
    const std::optional<MarkerPose> pose = EstimateMarkerPose(detection, unknown_size, camera);
    if (pose) frame.centres.push_back({detection.id, pose->Best().cam_from_marker.translation});
  }
  std::sort(frame.centres.begin(), frame.centres.end(),
            [](const Centre& a, const Centre& b) { return a.id < b.id; });
  if (frame.centres.empty()) return AmbiguityChoice::kNone;
  int votes[2] = {0, 0};
  for (const AmbiguousFrame& earlier : frames_) {
    int best[2] = {0, 0};  // per solution of the new frame, over the earlier frame's two
    for (int s = 0; s < 2; ++s) {
      for (int e = 0; e < 2; ++e) {
        best[s] = std::max(best[s], Agreeing(frame, frame.world_from_cam[s], earlier,
                                             earlier.world_from_cam[e]));
      }
    }
    if (best[0] >= best[1] + options_.min_agreement_margin) ++votes[0];
    if (best[1] >= best[0] + options_.min_agreement_margin) ++votes[1];
  }
  frames_.push_back(std::move(frame));
  if (static_cast<int>(frames_.size()) > options_.max_frames) frames_.pop_front();
  if (votes[0] >= options_.min_votes && votes[1] == 0) return AmbiguityChoice::kBest;
  if (votes[1] >= options_.min_votes && votes[0] == 0) return AmbiguityChoice::kAlternative;
  return AmbiguityChoice::kNone;
}

}  // namespace arucoslam
