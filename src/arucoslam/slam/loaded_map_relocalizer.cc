#include "arucoslam/slam/loaded_map_relocalizer.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/optim/pose_optimizer.h"
#include "arucoslam/optim/reprojection_error.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

// Keyframes compared with one frame that has no pose (round robin over the map, so a map of
// N keyframes is searched in N / 8 frames): brute-force matching against one keyframe takes
// about 10 ms (measured on a loaded machine: 150-200 ms per frame for 15 keyframes).
constexpr std::size_t kSeedKeyframesPerFrame = 8;
// Descriptor matches to map points that must remain inliers of the refined seed pose (as
// many as the tracker wants after its local-map search).
constexpr int kMinSeedInliers = 30;

}  // namespace

LoadedMapRelocalizer::LoadedMapRelocalizer(const TrackerOptions& tracking) : tracking_(tracking) {}

std::optional<int> LoadedMapRelocalizer::Relocalize(const Map& map, Tracker& tracker, Frame& frame,
                                                    std::size_t frame_index) {
  const std::optional<Rigid3> seed = SeedPose(map, frame);
  if (!seed) return std::nullopt;
  const TrackingResult result = tracker.TrackFromPose(frame, *seed);
  if (result.state != TrackingState::kTracking) return std::nullopt;
  ARUCOSLAM_LOG_DEBUG(
      "frame {}: relocalised in the loaded map, {} inliers, {:.2f} m from the seed pose",
      frame_index, result.num_inliers,
      (frame.cam_from_world->Inverse().translation - seed->Inverse().translation).norm());
  return result.num_inliers;
}

std::optional<Rigid3> LoadedMapRelocalizer::SeedPose(const Map& map, const Frame& frame) {
  const std::vector<KeyframeId> keyframes = map.Read([](const MapData& data) {
    std::vector<KeyframeId> ids;
    for (const auto& [id, keyframe] : data.keyframes()) ids.push_back(id);
    return ids;
  });
  if (keyframes.empty() || frame.features.size() == 0) return std::nullopt;
  // The keyframe sharing the most descriptor matches with map points among this frame's
  // share of the round robin; its matches are kept as 2D-3D correspondences.
  std::vector<PoseObservation> best;
  Rigid3 best_pose;
  const std::size_t count = std::min(kSeedKeyframesPerFrame, keyframes.size());
  for (std::size_t k = 0; k < count; ++k) {
    const KeyframeId id = keyframes[(next_keyframe_ + k) % keyframes.size()];
    map.Read([&](const MapData& data) {
      const Keyframe* keyframe = data.FindKeyframe(id);
      if (keyframe == nullptr) return 0;
      const std::vector<FeatureMatch> matches =
          MatchBruteForce(keyframe->features, frame.features, tracking_.reference_search);
      std::vector<PoseObservation> observations;
      for (const FeatureMatch& match : matches) {
        const MapPoint* point = data.FindMapPoint(keyframe->map_point_ids[match.index1]);
        if (point == nullptr) continue;
        observations.push_back(
            {point->p_in_world, frame.UndistortedPixel(match.index2), frame.SigmaPx(match.index2)});
      }
      if (observations.size() > best.size()) {
        best = std::move(observations);
        best_pose = keyframe->cam_from_world;
      }
      return 0;
    });
  }
  next_keyframe_ = (next_keyframe_ + count) % keyframes.size();
  if (static_cast<int>(best.size()) < kMinSeedInliers) return std::nullopt;
  PoseOptimizationOptions pose_options = tracking_.pose;
  pose_options.min_inliers = tracking_.min_pose_inliers;
  const PoseOptimizationResult refined =
      OptimizePose(best, best_pose, PinholeIntrinsics::FromCamera(frame.camera), pose_options);
  ARUCOSLAM_LOG_DEBUG("seed: {} matches, {} inliers, rms {:.2f} px", best.size(),
                      refined.num_inliers, refined.final_rms_px);
  if (!refined.success || refined.num_inliers < kMinSeedInliers) return std::nullopt;
  return refined.cam_from_world;
}

}  // namespace arucoslam
