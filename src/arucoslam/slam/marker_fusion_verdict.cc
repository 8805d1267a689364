// MarkerFusion's judgement of keypoint poses against the frame's marker location (agreement
// or a look-alike place), and the unaligned map's vote for its orientation.
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
  ARUCOSLAM_LOG_DEBUG("frame {}: keypoint pose {:.2f} m from the markers' location, rejected",
                      frame_index, MarkerOffset(*frame.cam_from_world).norm());
  ++stats_.num_rejected_poses;
  return PoseVerdict::kRejected;
}

void MarkerFusion::NoteTrackedFrame(const Frame& frame, bool world_aligned) {
  if (world_aligned || !ambiguous_location_ || !frame.cam_from_world) return;
  rotation_vote_.Add(*frame.cam_from_world, ambiguous_location_->world_from_cam,
                     *ambiguous_location_->alternative_world_from_cam);
  ambiguous_location_.reset();
}

void MarkerFusion::MapEnteredWorld() { rotation_vote_.Clear(); }

void MarkerFusion::MapReset() {
  rotation_vote_.Clear();
  covisible_vote_.Clear();
}

}  // namespace arucoslam
