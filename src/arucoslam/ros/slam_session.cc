#include "arucoslam/ros/slam_session.h"

#include <utility>

#include "arucoslam/exe/default_vocabulary.h"
#include "arucoslam/exe/slam_run.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/error.h"

namespace arucoslam {

SlamSession::SlamSession(const SlamSessionOptions& options) {
  if (!options.Check()) {
    throw InputError("num_features", "expected at least 100, got " +
                                         std::to_string(options.num_features));
  }
  const std::filesystem::path vocabulary =
      options.vocabulary.empty() ? DefaultVocabularyPath() : options.vocabulary;
  // The same System options as `arucoslam run`, so that both give the same poses.
  options_ = std::make_unique<SystemOptions>(
      DefaultRunOptions(options.blocking,
                        std::make_shared<const Vocabulary>(Vocabulary::Load(vocabulary)),
                        options.loop_closing));
  options_->extractor.num_features = options.num_features;
  options_->live_source = options.live_source;
  if (options.marker_map) {
    options_->marker_map = options.marker_map;
    options_->detector.dictionary = options.marker_map->dictionary;
  }
}

SlamSession::~SlamSession() = default;

void SlamSession::Start(const CameraModel& camera) {
  if (!camera.Check()) throw InputError("camera", "invalid camera model");
  camera_ = camera;
  system_ = std::make_unique<System>(camera, *options_);
}

SlamUpdate SlamSession::Process(const cv::Mat& grey, double timestamp_s) {
  const FrameReport report = system_->ProcessImage(grey, timestamp_s);
  SlamUpdate update;
  update.timestamp_s = timestamp_s;
  update.world_from_cam = report.online_world_from_cam;
  FrameStatus& status = update.status;
  status.state = TrackingStateName(report.state);
  status.has_pose = update.world_from_cam.has_value();
  status.relocalised = lost_ && report.cam_from_world.has_value();
  status.world_aligned = report.world_aligned;
  status.marker_pose = report.marker_pose;
  status.num_markers = report.num_markers;
  status.num_keyframes = system_->map().NumKeyframes();
  status.num_map_points = system_->map().NumMapPoints();
  lost_ = report.state == TrackingState::kLost && !report.cam_from_world;
  return update;
}

std::vector<Eigen::Vector3d> SlamSession::MapPoints() const {
  return system_ ? system_->MapPoints() : std::vector<Eigen::Vector3d>{};
}

MarkerMap SlamSession::Markers() const {
  if (system_ && finished_) return system_->MarkerMapOutput();
  return options_->marker_map.value_or(MarkerMap());
}

void SlamSession::Finish() {
  if (!system_ || finished_) return;
  system_->Finish();
  finished_ = true;
}

}  // namespace arucoslam
