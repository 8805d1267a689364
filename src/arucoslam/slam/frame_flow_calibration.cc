// FrameFlow's radial calibration: the mapping thread refines the camera's radial distortion
// from the map; the tracking thread hands the refined camera on to frames and kept matches.
#include "arucoslam/feature/undistort.h"
#include "arucoslam/slam/frame_flow.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

bool SameDistortion(const CameraModel& a, const CameraModel& b) {
  return a.model == b.model && a.distortion == b.distortion;
}

}  // namespace

CameraModel FrameFlow::Camera() const {
  std::lock_guard lock(camera_mutex_);
  return camera_;
}

void FrameFlow::FollowCalibration(Frame& frame) {
  const CameraModel camera = Camera();
  if (!SameDistortion(camera, tracked_camera_)) {
    pose_history_.Recalibrate(tracked_camera_, camera);
    tracked_camera_ = camera;
  }
  // A frame extracted while the mapping thread refined the calibration.
  if (!SameDistortion(frame.camera, camera) && frame.camera.fx == camera.fx &&
      frame.camera.fy == camera.fy && frame.camera.cx == camera.cx &&
      frame.camera.cy == camera.cy) {
    frame.camera = camera;
    UndistortFeatures(camera, &frame.features);
  }
}

void FrameFlow::CalibrateRadialDistortion() {
  CameraModel camera = Camera();
  const RadialCalibrationStep step = radial_calibration_.MaybeRefine(*map_, &camera);
  if (!step.attempted) return;
  ARUCOSLAM_LOG_INFO("radial calibration at {} keyframes: k {:+.4f}, cost {:.1f} -> {:.1f} ({})",
                     map_->NumKeyframes(), step.k, step.cost_without, step.cost_with,
                     step.message);
  if (!step.applied) return;
  {
    std::lock_guard lock(camera_mutex_);
    camera_ = camera;
  }
  std::lock_guard lock(*stats_mutex_);
  ++stats_->num_radial_calibrations;
  stats_->radial_k1_correction += step.k;
}

}  // namespace arucoslam
