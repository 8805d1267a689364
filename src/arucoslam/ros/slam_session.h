// SlamSession: the node's SLAM, one System fed frame by frame from one thread, with what the
// node publishes about each frame. Construct it (loads the vocabulary and checks the options,
// so bad files fail at start-up), Start it once the camera is known, then Process each image.
// The header has no ROS and no C++20 type (the node's ROS side builds as C++17).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/ros/frame_status.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

class System;
struct SystemOptions;

struct SlamSessionOptions {
  std::optional<MarkerMap> marker_map;  // known markers; unset: keypoints only
  std::filesystem::path vocabulary;     // empty: the default one shipped with arucoslam
  bool loop_closing = true;
  int num_features = 1000;  // ORB features per image
  // false: local mapping on its own thread (the node's default); true: each frame tracked and
  // mapped before Process returns (deterministic).
  bool blocking = false;
  // Threaded: frames come at the camera's pace and are dropped while tracking waits, so
  // tracking never waits for the young map (SystemOptions::live_source). Off by default:
  // fed one frame at a time, the node keeps the wait of recorded sequences.
  bool live_source = false;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("num_features", num_features, 100);
    return check.ok();
  }
};

struct SlamUpdate {
  double timestamp_s = 0.0;
  // The camera pose to publish: with a marker map only once it is in the marker world (marker
  // pose or world-aligned map), without one in the map's own frame.
  std::optional<Rigid3> world_from_cam;
  FrameStatus status;
};

class SlamSession {
 public:
  // Throws InputError for a bad vocabulary file or options.
  explicit SlamSession(const SlamSessionOptions& options);
  ~SlamSession();
  SlamSession(const SlamSession&) = delete;
  SlamSession& operator=(const SlamSession&) = delete;

  // Creates the System for `camera` (InputError when the camera fails its checks).
  void Start(const CameraModel& camera);
  bool started() const { return system_ != nullptr; }
  const CameraModel& camera() const { return camera_; }

  // One 8-bit grey image of the camera's size; timestamps must increase. Needs Start.
  SlamUpdate Process(const cv::Mat& grey, double timestamp_s);
  // Map points in the published frame (none with a marker map before world alignment).
  std::vector<Eigen::Vector3d> MapPoints() const;
  // Known markers, and after Finish also the ones mapped online.
  MarkerMap Markers() const;
  // Waits for the mapping thread and runs the end-of-run adjustments; Process may not be
  // called after it.
  void Finish();

 private:
  std::unique_ptr<SystemOptions> options_;
  CameraModel camera_;
  std::unique_ptr<System> system_;
  bool lost_ = false;  // the previous frame was lost
  bool finished_ = false;
};

}  // namespace arucoslam
