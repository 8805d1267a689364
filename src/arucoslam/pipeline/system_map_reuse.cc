// System's map reuse: starting from a saved map, the localisation-only mode, and a minimal
// relocalisation into a loaded map from keyframe matches (no vocabulary needed).
#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/optim/pose_optimizer.h"
#include "arucoslam/optim/reprojection_error.h"
#include "arucoslam/pipeline/system.h"
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

void System::StartFromMap(MapData map, bool world_aligned, bool localize_only) {
  if (num_frames_ != 0 || finished_) {
    throw std::logic_error("System::StartFromMap after the first frame");
  }
  if (map.NumKeyframes() == 0) throw std::invalid_argument("System::StartFromMap: empty map");
  map_->Write([&map](MapData& data) { data = std::move(map); });
  map_loaded_ = true;
  localize_only_ = localize_only;
  anchoring_.StartLoadedMap(world_aligned);
  if (places_) {
    places_->SetMetricMap(world_aligned);
    places_->IndexExistingKeyframes();
  }
}

void System::LocalizeInLoadedMap(Frame& frame, FrameReport& report) {
  report.state = TrackingState::kNotInitialized;
  if (!RelocalizeWithMarkers(frame, report) && !RelocalizeWithPlaces(frame, report) &&
      !RelocalizeInLoadedMap(frame, report)) {
    report.message = "not localised in the loaded map";
    return;
  }
  last_state_ = TrackingState::kTracking;
  frames_since_keyframe_ = 0;
  report.state = TrackingState::kTracking;
  report.cam_from_world = frame.cam_from_world;
  RecordPose(frame, tracker_->reference_keyframe());
}

bool System::RelocalizeInLoadedMap(Frame& frame, FrameReport& report) {
  // Brute-force keyframe matching, for a loaded map without a place database only.
  if (!map_loaded_ || places_) return false;
  const std::optional<Rigid3> seed = SeedPoseFromKeyframes(frame);
  if (!seed) return false;
  const TrackingResult result = tracker_->TrackFromPose(frame, *seed);
  if (result.state != TrackingState::kTracking) return false;
  report.num_inliers = result.num_inliers;
  report.message = "relocalised in the loaded map";
  ARUCOSLAM_LOG_DEBUG(
      "frame {}: relocalised in the loaded map, {} inliers, {:.2f} m from the seed pose",
      report.index, result.num_inliers,
      (frame.cam_from_world->Inverse().translation - seed->Inverse().translation).norm());
  std::lock_guard lock(stats_mutex_);
  ++stats_.num_map_relocalizations;
  return true;
}

std::optional<Rigid3> System::SeedPoseFromKeyframes(const Frame& frame) {
  const std::vector<KeyframeId> keyframes = map_->Read([](const MapData& data) {
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
    const KeyframeId id = keyframes[(next_seed_keyframe_ + k) % keyframes.size()];
    map_->Read([&](const MapData& data) {
      const Keyframe* keyframe = data.FindKeyframe(id);
      if (keyframe == nullptr) return 0;
      const std::vector<FeatureMatch> matches =
          MatchBruteForce(keyframe->features, frame.features, options_.tracker.reference_search);
      std::vector<PoseObservation> observations;
      for (const FeatureMatch& match : matches) {
        const MapPoint* point = data.FindMapPoint(keyframe->map_point_ids[match.index1]);
        if (point == nullptr) continue;
        observations.push_back({point->p_in_world, frame.UndistortedPixel(match.index2),
                                frame.SigmaPx(match.index2)});
      }
      if (observations.size() > best.size()) {
        best = std::move(observations);
        best_pose = keyframe->cam_from_world;
      }
      return 0;
    });
  }
  next_seed_keyframe_ = (next_seed_keyframe_ + count) % keyframes.size();
  if (static_cast<int>(best.size()) < kMinSeedInliers) return std::nullopt;
  PoseOptimizationOptions pose_options = options_.tracker.pose;
  pose_options.min_inliers = options_.tracker.min_pose_inliers;
  const PoseOptimizationResult refined = OptimizePose(
      best, best_pose, PinholeIntrinsics::FromCamera(frame.camera), pose_options);
  ARUCOSLAM_LOG_DEBUG("seed: {} matches, {} inliers, rms {:.2f} px", best.size(),
                      refined.num_inliers, refined.final_rms_px);
  if (!refined.success || refined.num_inliers < kMinSeedInliers) return std::nullopt;
  return refined.cam_from_world;
}

}  // namespace arucoslam
