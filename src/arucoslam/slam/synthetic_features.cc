#include "arucoslam/slam/synthetic_features.h"

#include <algorithm>

#include "arucoslam/slam/synthetic_descriptors.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool SyntheticFeatureOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("num_points", num_points, 0);
  check.Require((box_max - box_min).minCoeff() >= 0.0, "box_max", ">= box_min in every axis");
  check.AtLeast("pixel_noise", pixel_noise, 0.0);
  check.AtLeast("flipped_bits", flipped_bits, 0);
  check.AtLeast("num_distractors", num_distractors, 0);
  check.AtLeast("border_px", border_px, 0.0);
  return check.ok();
}

SyntheticFeatureScene::SyntheticFeatureScene(const CameraModel& camera,
                                             const SyntheticFeatureOptions& options)
    : camera_(camera), options_(options), random_(options.seed) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int j = 0; j < options_.num_points; ++j) {
    Eigen::Vector3d p;
    for (int axis = 0; axis < 3; ++axis) {
      p[axis] = options_.box_min[axis] +
                unit(random_) * (options_.box_max[axis] - options_.box_min[axis]);
    }
    points_.push_back(p);
    descriptors_.push_back(RandomDescriptor());
  }
}

OrbDescriptor SyntheticFeatureScene::RandomDescriptor() { return RandomOrbDescriptor(random_); }

Frame SyntheticFeatureScene::MakeFrame(FrameId id, double timestamp_s,
                                       const Rigid3& cam_from_world, std::vector<int>* truth) {
  std::normal_distribution<double> noise(0.0, options_.pixel_noise);
  std::uniform_real_distribution<double> u(options_.border_px, camera_.width - options_.border_px);
  std::uniform_real_distribution<double> v(options_.border_px, camera_.height - options_.border_px);
  struct Entry {
    Eigen::Vector2d pixel;
    OrbDescriptor descriptor;
    int point;
  };
  std::vector<Entry> entries;
  for (std::size_t j = 0; j < points_.size(); ++j) {
    const Eigen::Vector3d p_in_cam = cam_from_world * points_[j];
    if (!(p_in_cam.z() > 0.0)) continue;
    const auto pixel = camera_.Project(p_in_cam);
    if (!pixel || !camera_.InImage(*pixel, options_.border_px)) continue;
    OrbDescriptor d = descriptors_[j];
    FlipRandomBits(options_.flipped_bits, random_, &d);
    entries.push_back({*pixel + Eigen::Vector2d(noise(random_), noise(random_)), d,
                       static_cast<int>(j)});
  }
  for (int k = 0; k < options_.num_distractors; ++k) {
    entries.push_back({Eigen::Vector2d(u(random_), v(random_)), RandomDescriptor(), -1});
  }
  std::shuffle(entries.begin(), entries.end(), random_);
  Frame frame;
  frame.id = id;
  frame.timestamp_s = timestamp_s;
  frame.camera = camera_;
  frame.features.pyramid = ScalePyramid::Make(8, 1.2);
  frame.features.image_width = camera_.width;
  frame.features.image_height = camera_.height;
  frame.features.descriptors =
      cv::Mat(static_cast<int>(entries.size()), kOrbDescriptorBytes, CV_8U);
  truth->clear();
  for (std::size_t i = 0; i < entries.size(); ++i) {
    cv::KeyPoint keypoint(static_cast<float>(entries[i].pixel.x()),
                          static_cast<float>(entries[i].pixel.y()), 31.0f, 0.0f);
    keypoint.octave = 0;
    frame.features.keypoints.push_back(keypoint);
    frame.features.undistorted.push_back(camera_.Unproject(entries[i].pixel));
    std::copy(entries[i].descriptor.begin(), entries[i].descriptor.end(),
              frame.features.descriptors.ptr(static_cast<int>(i)));
    truth->push_back(entries[i].point);
  }
  frame.ResetMatches();
  return frame;
}

}  // namespace arucoslam
