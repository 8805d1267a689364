#include "arucoslam/slam/synthetic_loop_map.h"

#include <array>
#include <cmath>
#include <map>
#include <random>

#include "arucoslam/slam/synthetic_descriptors.h"

namespace arucoslam {
namespace {

using Descriptor = std::array<std::uint8_t, kOrbDescriptorBytes>;

CameraModel LoopCamera() {
  return PinholeCamera(640, 480, 500.0);
}

struct Wall {
  std::vector<Eigen::Vector3d> points;
  std::vector<Descriptor> descriptors;
};

Wall MakeWall(int count, std::mt19937& random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Wall wall;
  for (int j = 0; j < count; ++j) {
    const double angle = 2.0 * M_PI * unit(random);
    const double radius = 15.0 + 2.0 * unit(random);
    wall.points.emplace_back(radius * std::cos(angle), 4.0 * unit(random) - 2.0,
                             radius * std::sin(angle));
    wall.descriptors.push_back(RandomOrbDescriptor(random));
  }
  return wall;
}

// The keyframe seen from `truth`; returns the wall index of each keypoint.
std::vector<int> MakeView(const Wall& wall, const Rigid3& truth, int max_flipped_bits,
                          std::mt19937& random, Keyframe* keyframe) {
  const CameraModel camera = LoopCamera();
  keyframe->camera = camera;
  keyframe->features.pyramid = ScalePyramid::Make(8, 1.2);
  std::vector<int> wall_indices;
  std::vector<Descriptor> rows;
  for (std::size_t j = 0; j < wall.points.size(); ++j) {
    const Eigen::Vector3d p = truth * wall.points[j];
    const std::optional<Eigen::Vector2d> pixel = camera.Project(p);
    if (!pixel || !camera.InImage(*pixel, 5.0)) continue;
    cv::KeyPoint keypoint(pixel->x(), pixel->y(), 31.0f, 0.0f);
    keypoint.octave = 0;
    keyframe->features.keypoints.push_back(keypoint);
    keyframe->features.undistorted.emplace_back(p.x() / p.z(), p.y() / p.z());
    Descriptor row = wall.descriptors[j];
    const int flips = static_cast<int>(random() % (max_flipped_bits + 1));
    for (int flip = 0; flip < flips; ++flip) {
      row[random() % kOrbDescriptorBytes] ^= 1 << (random() % 8);
    }
    rows.push_back(row);
    wall_indices.push_back(static_cast<int>(j));
  }
  keyframe->features.descriptors =
      cv::Mat(static_cast<int>(rows.size()), kOrbDescriptorBytes, CV_8U);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    std::copy(rows[r].begin(), rows[r].end(),
              keyframe->features.descriptors.ptr<std::uint8_t>(static_cast<int>(r)));
  }
  keyframe->map_point_ids.assign(rows.size(), MapPointId());
  return wall_indices;
}

}  // namespace

SyntheticLoopMap BuildSyntheticLoopMap(const SyntheticLoopMapOptions& options, Map* map) {
  SyntheticLoopMap scene;
  scene.loop = MakeSyntheticLoop(options.loop);
  double scale = 1.0;
  for (int i = 0; i < options.loop.num_keyframes; ++i, scale *= options.loop.scale_drift) {
    scene.local_scales.push_back(scale);
  }
  std::mt19937 random(options.seed);
  const Wall wall = MakeWall(options.num_wall_points, random);
  std::map<int, std::pair<MapPointId, int>> last_point;  // wall index -> (point, creator)
  map->Write([&](MapData& data) {
    for (int i = 0; i < options.loop.num_keyframes; ++i) {
      const Rigid3& truth = scene.loop.truth_cam_from_world[i];
      Keyframe keyframe;
      const std::vector<int> wall_indices =
          MakeView(wall, truth, options.max_flipped_bits, random, &keyframe);
      const Sim3& estimate = scene.loop.problem.nodes[i].cam_from_world;
      keyframe.cam_from_world = Rigid3(estimate.rotation, estimate.translation);
      const Rigid3 world_from_estimate = keyframe.cam_from_world.Inverse();
      const KeyframeId id = data.AddKeyframe(std::move(keyframe));
      scene.keyframes.push_back(id);
      for (std::size_t k = 0; k < wall_indices.size(); ++k) {
        const int w = wall_indices[k];
        auto it = last_point.find(w);
        if (it == last_point.end() || it->second.second < i - 1) {
          MapPoint point;
          point.p_in_world =
              world_from_estimate * (scene.local_scales[i] * (truth * wall.points[w]));
          point.reference_keyframe = id;
          it = last_point.insert_or_assign(w, std::make_pair(data.AddMapPoint(point), i)).first;
        }
        data.AddObservation(id, static_cast<int>(k), it->second.first);
      }
    }
    std::vector<MapPointId> ids;
    for (const auto& [id, point] : data.map_points()) ids.push_back(id);
    for (const MapPointId& id : ids) {
      data.UpdateDescriptor(id);
      data.UpdateNormalAndDepth(id);
    }
  });
  return scene;
}

double KeyframeCentreRms(const Map& map, const SyntheticLoopMap& scene) {
  return map.Read([&](const MapData& data) {
    double sum = 0.0;
    for (std::size_t i = 0; i < scene.keyframes.size(); ++i) {
      sum += (data.FindKeyframe(scene.keyframes[i])->CameraCenter() -
              scene.loop.truth_cam_from_world[i].Inverse().translation)
                 .squaredNorm();
    }
    return scene.keyframes.empty() ? 0.0 : std::sqrt(sum / scene.keyframes.size());
  });
}

}  // namespace arucoslam
