// `run`'s ROS 1 bag input: a FrameSource over one image topic of a bag (io/rosbag/bag_reader.h). In a
// build without ROS, opening a bag is an InputError that says so.
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "arucoslam/io/frame_source.h"

namespace arucoslam {

struct BagFeedOptions {
  std::string image_topic;
  std::string camera_info_topic;      // empty: the image topic's namespace + /camera_info
  std::filesystem::path camera_path;  // calibration file instead of the bag's camera_info
};

// `--dataset` names a bag: a path ending in .bag.
bool IsBagDataset(const std::filesystem::path& path);

// Throws InputError naming the bag (see BagImageSource::Open) or, without ROS, saying so.
std::unique_ptr<FrameSource> OpenBagSource(const std::filesystem::path& path,
                                           const BagFeedOptions& options);

}  // namespace arucoslam
