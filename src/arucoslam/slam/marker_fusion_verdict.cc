// MarkerFusion's judgement of keypoint poses against the frame's marker location: agreement,
// drift to correct, or a look-alike place; and the unaligned map's vote for its orientation.
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

Eigen::Vector3d MarkerFusion::MarkerOffset(const Rigid3& cam_from_world) const {
  return fix_->world_from_cam.translation - cam_from_world.Inverse().translation;
}

bool MarkerFusion::Contradicts(const Rigid3& cam_from_world) const {
  return fix_ && MarkerOffset(cam_from_world).norm() > options_.max_marker_disagreement_m;
}

bool MarkerFusion::Confirms(const Rigid3& cam_from_world) const {
  return fix_ && !Contradicts(cam_from_world);
}

PoseVerdict MarkerFusion::JudgeTrackedPose(const Frame& frame, bool world_aligned,
                                           std::size_t frame_index) {
  if (!world_aligned || !Contradicts(*frame.cam_from_world)) return PoseVerdict::kAccepted;
  if (TakeDisagreementAsDrift(frame, frame_index)) return PoseVerdict::kDrift;
  ARUCOSLAM_LOG_DEBUG("frame {}: keypoint pose {:.2f} m from the markers' location, rejected",
                      frame_index, MarkerOffset(*frame.cam_from_world).norm());
  ++stats_.num_rejected_poses;
  return PoseVerdict::kRejected;
}

bool MarkerFusion::TakeDisagreementAsDrift(const Frame& frame, std::size_t frame_index) {
  if (!options_.correct_drift_beyond_gate || !markers_agreed_s_ || !fix_->known_markers_only) {
    return false;
  }
  const Eigen::Vector3d offset = MarkerOffset(*frame.cam_from_world);
  if (drift_frames_ == 0) {
    // Drift builds up out of the markers' sight or grows a little from frame to frame; a
    // jump away from where the markers just agreed is a wrong place.
    const bool long_unseen =
        frame.timestamp_s - *markers_agreed_s_ >= options_.min_drift_interval_s;
    const bool gradual =
        last_marker_offset_ && (offset - *last_marker_offset_).norm() <= options_.max_drift_step_m;
    if (!long_unseen && !gradual) return false;
    ARUCOSLAM_LOG_DEBUG(
        "frame {}: keypoint pose {:.2f} m from the markers' location, {:.1f} s "
        "after they last agreed: drift, the map is corrected",
        frame_index, offset.norm(), frame.timestamp_s - *markers_agreed_s_);
    drift_keyframe_wanted_ = true;
    ++stats_.num_drift_disagreements;
  }
  // The correction did not bring the map back in time: from here on a look-alike place.
  if (++drift_frames_ > options_.max_drift_correction_frames) {
    ForgetAgreement();
    return false;
  }
  return true;
}

void MarkerFusion::NoteTrackedFrame(const Frame& frame, bool relocalized, bool world_aligned) {
  if (world_aligned) {
    NoteAgreement(frame, relocalized);
  } else {
    VoteForWorldRotation(frame);
  }
}

void MarkerFusion::NoteAgreement(const Frame& frame, bool relocalized) {
  const bool agrees = fix_ && !Contradicts(*frame.cam_from_world);
  if (relocalized && !agrees) {  // not confirmed by the markers: a break in the tracking
    ForgetAgreement();
    return;
  }
  if (fix_) last_marker_offset_ = MarkerOffset(*frame.cam_from_world);
  if (agrees) {
    markers_agreed_s_ = frame.timestamp_s;
    drift_frames_ = 0;
    drift_keyframe_wanted_ = false;
  }
}

void MarkerFusion::VoteForWorldRotation(const Frame& frame) {
  if (!ambiguous_location_ || !frame.cam_from_world) return;
  rotation_vote_.Add(*frame.cam_from_world, ambiguous_location_->world_from_cam,
                     *ambiguous_location_->alternative_world_from_cam);
  ambiguous_location_.reset();
}

void MarkerFusion::ForgetAgreement() {
  markers_agreed_s_.reset();
  last_marker_offset_.reset();
  drift_frames_ = 0;
  drift_keyframe_wanted_ = false;
}

void MarkerFusion::MapEnteredWorld(double timestamp_s) {
  markers_agreed_s_ = timestamp_s;
  last_marker_offset_.reset();
  rotation_vote_.Clear();
}

void MarkerFusion::MapReset() {
  rotation_vote_.Clear();
  covisible_vote_.Clear();
  ForgetAgreement();
}

}  // namespace arucoslam
