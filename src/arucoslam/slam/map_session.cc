#include "arucoslam/slam/map_session.h"

#include <utility>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool MapSessionOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("reset_max_keyframes", reset_max_keyframes, 0);
  check.AtLeast("marker_reset_lost_frames", marker_reset_lost_frames, 1);
  check.Above("new_map_after_lost_s", new_map_after_lost_s, 0.0);
  check.Nested("bridge_motion", bridge_motion);
  check.Above("bridge_position_sigma_m", bridge_position_sigma_m, 0.0);
  check.AtLeast("bridge_position_sigma_per_s", bridge_position_sigma_per_s, 0.0);
  check.Above("bridge_rotation_sigma_rad", bridge_rotation_sigma_rad, 0.0);
  check.AtLeast("bridge_rotation_sigma_per_s", bridge_rotation_sigma_per_s, 0.0);
  check.AtLeast("bridge_max_acceleration_m_s2", bridge_max_acceleration_m_s2, 0.0);
  check.AtLeast("max_backfill_frames", max_backfill_frames, 0);
  return check.ok();
}

MapSession::MapSession(const MapSessionOptions& options, bool marker_world)
    : options_(options), marker_world_(marker_world), motion_at_close_(options.bridge_motion) {}

LossAction MapSession::OnLostFrame(const Frame& frame, const LostMapState& map) {
  const bool stuck =
      map.frame_has_marker_fix && ++lost_with_markers_ >= options_.marker_reset_lost_frames;
  const bool young = static_cast<int>(map.num_keyframes) <= options_.reset_max_keyframes;
  if (map.loaded) return LossAction::kKeep;
  // A frame the markers located keeps that pose (in the world, whatever the next map does).
  if (!map.frame_has_marker_fix) KeepLostFrame(frame);
  if (LostTooLong(frame.timestamp_s)) {
    ++stats_.num_new_maps_after_loss;
    return LossAction::kNewMap;
  }
  // A map in the marker world is kept (markers relocalise into it) unless it is stuck.
  if (stuck || (young && !map.world_aligned)) return LossAction::kReset;
  return LossAction::kKeep;
}

void MapSession::OnTrackedFrame() {
  lost_frames_.clear();
  lost_with_markers_ = 0;
  lost_since_s_.reset();
}

bool MapSession::LostTooLong(double timestamp_s) {
  if (!lost_since_s_) lost_since_s_ = timestamp_s;
  return timestamp_s - *lost_since_s_ >= options_.new_map_after_lost_s;
}

MapClosing MapSession::DecideClosing(std::size_t num_keyframes, bool world_aligned) {
  if (num_keyframes == 0) return MapClosing::kNothing;
  if (!marker_world_) {
    // Keypoints only: maps are in unrelated frames; the biggest one is the output.
    return num_keyframes > biggest_closed_keyframes_ ? MapClosing::kBiggestKeypointMap
                                                     : MapClosing::kNothing;
  }
  if (!world_aligned) {
    ++stats_.num_maps_discarded;
    return MapClosing::kDiscarded;
  }
  return MapClosing::kInWorld;
}

void MapSession::KeepBiggestKeypointMap(std::vector<StampedPose> poses, std::size_t num_keyframes) {
  biggest_closed_poses_ = std::move(poses);
  biggest_closed_keyframes_ = num_keyframes;
}

bool MapSession::CloseWorldMap(const Map& map, ClosingWorldMap closing) {
  motion_at_close_.Clear();
  if (options_.bridge_tracking_gaps) {
    for (const StampedPose& pose : closing.motion_poses) {
      motion_at_close_.Add(pose.timestamp_s, pose.world_from_cam);
    }
  }
  ClosedMap closed;
  closed.output_keyframes_before = closed_keyframes_.size();
  closed.output_points_before = closed_points_.size();
  closed_keyframes_ = std::move(closing.keyframes);
  closed_points_ = std::move(closing.points);
  if (!options_.merge_closed_maps) return false;
  closed.data = map.Read([](const MapData& data) { return data; });
  closed.keyframe_fixes = std::move(closing.keyframe_fixes);
  closed_map_ = std::move(closed);  // an older one not merged stays in the outputs only
  return true;
}

void MapSession::StartNewMap(std::optional<int> closed_marker_generation) {
  if (closed_marker_generation && closed_map_) {
    closed_map_->marker_generation = *closed_marker_generation;
  }
  // The frames lost before the reset are the oldest the next map's backfill tries.
  initialisation_frames_ = std::move(lost_frames_);
  lost_frames_.clear();
  absorbed_keyframes_.clear();
  bridge_priors_.clear();
  bridge_adjustment_priors_.clear();
  held_bridge_priors_.clear();
  lost_with_markers_ = 0;
  lost_since_s_.reset();
  ++stats_.num_resets;
}

const std::vector<StampedPose>* MapSession::BiggerClosedMapPoses(
    std::size_t current_keyframes) const {
  if (marker_world_ || current_keyframes >= biggest_closed_keyframes_) return nullptr;
  return &biggest_closed_poses_;
}

}  // namespace arucoslam
