#include "arucoslam/slam/synthetic_route_map.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <stdexcept>

#include "arucoslam/slam/synthetic_descriptors.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

double Radians(double degrees) { return degrees * M_PI / 180.0; }

Eigen::Vector3d Outward(double azimuth_deg) {
  return {std::cos(Radians(azimuth_deg)), 0.0, std::sin(Radians(azimuth_deg))};
}

}  // namespace

bool SyntheticRouteOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("num_wall_points", num_wall_points, 0);
  check.InRange("route_radius_m", route_radius_m, 0.0, 14.0, Interval::kClosedOpen);
  check.AtLeast("pixel_noise", pixel_noise, 0.0);
  check.AtLeast("max_flipped_bits", max_flipped_bits, 0);
  check.AtLeast("keyframe_distractors", keyframe_distractors, 0);
  return check.ok();
}

SyntheticRoute::SyntheticRoute(const SyntheticRouteOptions& options)
    : options_(options), random_(options.seed) {
  if (!options.Check()) throw std::invalid_argument("SyntheticRouteOptions: bad options");
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int j = 0; j < options.num_wall_points; ++j) {
    const double azimuth = 360.0 * unit(random_);
    const double radius = 15.0 + 2.0 * unit(random_);
    Eigen::Vector3d p = radius * Outward(azimuth);
    p.y() = 4.0 * unit(random_) - 2.0;
    wall_.push_back(p);
    descriptors_.push_back(RandomDescriptor());
  }
}

CameraModel SyntheticRoute::Camera() {
  return PinholeCamera(640, 480, 500.0);
}

Rigid3 SyntheticRoute::CamFromWorld(double azimuth_deg, double yaw_deg, double radial_m) const {
  const Eigen::Vector3d z = Outward(azimuth_deg + yaw_deg);
  const Eigen::Vector3d y(0.0, 1.0, 0.0);
  Eigen::Matrix3d world_from_cam_rotation;
  world_from_cam_rotation << y.cross(z), y, z;
  const Eigen::Vector3d centre = (options_.route_radius_m + radial_m) * Outward(azimuth_deg);
  return Rigid3(world_from_cam_rotation, centre).Inverse();
}

OrbDescriptor SyntheticRoute::RandomDescriptor() { return RandomOrbDescriptor(random_); }

std::vector<MarkerObservation> SyntheticRoute::VisibleMarkers(const Rigid3& cam_from_world) const {
  const CameraModel camera = Camera();
  std::vector<MarkerObservation> seen;
  for (const auto& [id, azimuth] : options_.markers) {
    const Eigen::Vector3d centre = 15.0 * Outward(azimuth);
    const Eigen::Vector3d right = Outward(azimuth + 90.0);  // tangent of the wall
    const Eigen::Vector3d down(0.0, 1.0, 0.0);
    const double offsets[4][2] = {{-0.25, -0.25}, {0.25, -0.25}, {0.25, 0.25}, {-0.25, 0.25}};
    MarkerObservation observation;
    observation.marker_id = MarkerId(id);
    bool visible = true;
    for (int c = 0; c < 4 && visible; ++c) {
      const Eigen::Vector3d corner = centre + offsets[c][0] * right + offsets[c][1] * down;
      const std::optional<Eigen::Vector2d> pixel = camera.Project(cam_from_world * corner);
      visible = pixel && camera.InImage(*pixel);
      if (visible) observation.corners_px[c] = *pixel;
    }
    if (visible) seen.push_back(observation);
  }
  return seen;
}

Frame SyntheticRoute::MakeFrame(FrameId id, const Rigid3& cam_from_world, int num_distractors,
                                std::vector<int>* truth) {
  const CameraModel camera = Camera();
  std::normal_distribution<double> noise(0.0, options_.pixel_noise);
  std::uniform_real_distribution<double> u(5.0, camera.width - 6.0);
  std::uniform_real_distribution<double> v(5.0, camera.height - 6.0);
  std::vector<std::pair<Eigen::Vector2d, int>> entries;
  for (std::size_t j = 0; j < wall_.size(); ++j) {
    const std::optional<Eigen::Vector2d> pixel = camera.Project(cam_from_world * wall_[j]);
    if (!pixel || !camera.InImage(*pixel, 5.0)) continue;
    entries.emplace_back(*pixel + Eigen::Vector2d(noise(random_), noise(random_)),
                         static_cast<int>(j));
  }
  for (int k = 0; k < num_distractors; ++k) {
    entries.emplace_back(Eigen::Vector2d(u(random_), v(random_)), -1);
  }
  std::shuffle(entries.begin(), entries.end(), random_);
  Frame frame;
  frame.id = id;
  frame.camera = camera;
  frame.features.pyramid = ScalePyramid::Make(8, 1.2);
  frame.features.image_width = camera.width;
  frame.features.image_height = camera.height;
  frame.features.descriptors =
      cv::Mat(static_cast<int>(entries.size()), kOrbDescriptorBytes, CV_8U);
  truth->clear();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto& [pixel, point] = entries[i];
    cv::KeyPoint keypoint(static_cast<float>(pixel.x()), static_cast<float>(pixel.y()), 31.0f,
                          0.0f);
    keypoint.octave = 0;
    frame.features.keypoints.push_back(keypoint);
    frame.features.undistorted.push_back(camera.Unproject(pixel));
    OrbDescriptor d = point >= 0 ? descriptors_[point] : RandomDescriptor();
    const int flips =
        point >= 0 ? static_cast<int>(random_() % (options_.max_flipped_bits + 1)) : 0;
    FlipRandomBits(flips, random_, &d);
    std::copy(d.begin(), d.end(), frame.features.descriptors.ptr(static_cast<int>(i)));
    truth->push_back(point);
  }
  frame.markers = VisibleMarkers(cam_from_world);
  frame.ResetMatches();
  return frame;
}

std::vector<KeyframeId> SyntheticRoute::AddRoute(const std::vector<Rigid3>& route, Map* map) {
  std::vector<KeyframeId> ids;
  std::map<int, MapPointId> previous;  // wall index -> point, of the previous keyframe
  for (const Rigid3& cam_from_world : route) {
    std::vector<int> truth;
    Frame frame = MakeFrame(FrameId(keyframe_truth_.size()), cam_from_world,
                            options_.keyframe_distractors, &truth);
    frame.cam_from_world = cam_from_world;
    std::map<int, MapPointId> current;
    map->Write([&](MapData& data) {
      const KeyframeId id = data.AddKeyframe(Keyframe::FromFrame(frame));
      ids.push_back(id);
      for (std::size_t k = 0; k < truth.size(); ++k) {
        const int w = truth[k];
        if (w < 0) continue;
        const auto it = previous.find(w);
        MapPointId point_id;
        if (it != previous.end()) {
          point_id = it->second;
        } else {
          MapPoint point;
          point.p_in_world = wall_[w];
          point.reference_keyframe = id;
          point_id = data.AddMapPoint(point);
        }
        data.AddObservation(id, static_cast<int>(k), point_id);
        current[w] = point_id;
      }
      for (const auto& [w, point_id] : current) {
        data.UpdateDescriptor(point_id);
        data.UpdateNormalAndDepth(point_id);
      }
    });
    previous = std::move(current);
    std::vector<int> seen;
    for (const int w : truth) {
      if (w >= 0) seen.push_back(w);
    }
    std::sort(seen.begin(), seen.end());
    keyframe_truth_.push_back(std::move(seen));
  }
  return ids;
}

int SyntheticRoute::SharedWallPoints(std::size_t a, std::size_t b) const {
  const std::vector<int>& first = keyframe_truth_.at(a);
  const std::vector<int>& second = keyframe_truth_.at(b);
  std::vector<int> shared;
  std::set_intersection(first.begin(), first.end(), second.begin(), second.end(),
                        std::back_inserter(shared));
  return static_cast<int>(shared.size());
}

}  // namespace arucoslam
