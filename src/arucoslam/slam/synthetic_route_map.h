// SyntheticRoute: a camera driven on a circle looking out at a textured cylindrical wall with
// optional markers, building a map of keyframes along any route, for place-recognition tests.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/map/map_point.h"

namespace arucoslam {

struct SyntheticRouteOptions {
  int num_wall_points = 4000;     // on a wall 15-17 m from the centre, 4 m high (y in [-2, 2])
  double route_radius_m = 10.0;   // the camera moves on this circle, looking outward
  double pixel_noise = 0.3;       // keypoint noise, pixels (std)
  int max_flipped_bits = 2;       // per observation, 0..max descriptor bits are flipped
  int keyframe_distractors = 50;  // keypoints with random descriptors per keyframe
  // Square markers (id, azimuth in degrees) of side 0.5 m on the wall at 15 m, facing in.
  std::vector<std::pair<int, double>> markers;
  std::uint32_t seed = 5;

  bool Check(std::string* why = nullptr) const;
};

class SyntheticRoute {
 public:
  explicit SyntheticRoute(const SyntheticRouteOptions& options = {});

  // 640 x 480 pinhole, f = 500 px, no distortion.
  static CameraModel Camera();
  // Camera on the route circle at `azimuth_deg` (0: +x, 90: +z), looking outward, turned
  // by `yaw_deg` to the left of outward and pushed `radial_m` outward.
  Rigid3 CamFromWorld(double azimuth_deg, double yaw_deg = 0.0, double radial_m = 0.0) const;

  // The frame seen from `cam_from_world` (features at level 0, angle 0, `undistorted` filled,
  // matches reset, pose empty, visible markers); truth[i] is keypoint i's wall point, -1 for
  // a distractor.
  Frame MakeFrame(FrameId id, const Rigid3& cam_from_world, int num_distractors,
                  std::vector<int>* truth);

  // Adds one keyframe per pose of the route (true poses; points at true positions). A wall
  // point seen by the previous keyframe of the route is the same map point; otherwise a new
  // one is made, so a place seen again after a gap gets duplicates, as drift would leave it.
  std::vector<KeyframeId> AddRoute(const std::vector<Rigid3>& route, Map* map);

  // Wall points seen by both keyframes `a` and `b` (indices into the AddRoute order).
  int SharedWallPoints(std::size_t a, std::size_t b) const;
  const std::vector<std::vector<int>>& keyframe_truth() const { return keyframe_truth_; }
  const std::vector<Eigen::Vector3d>& wall() const { return wall_; }

 private:
  OrbDescriptor RandomDescriptor();
  std::vector<MarkerObservation> VisibleMarkers(const Rigid3& cam_from_world) const;

  SyntheticRouteOptions options_;
  std::mt19937 random_;
  std::vector<Eigen::Vector3d> wall_;
  std::vector<OrbDescriptor> descriptors_;
  std::vector<std::vector<int>> keyframe_truth_;  // per added keyframe: sorted wall indices
};

}  // namespace arucoslam
