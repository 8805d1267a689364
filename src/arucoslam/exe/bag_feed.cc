#include "arucoslam/exe/bag_feed.h"

#include <memory>

#include "arucoslam/util/error.h"
#ifdef ARUCOSLAM_WITH_ROS
#include "arucoslam/ros/bag_reader.h"
#endif

namespace arucoslam {

bool IsBagDataset(const std::filesystem::path& path) { return path.extension() == ".bag"; }

#ifdef ARUCOSLAM_WITH_ROS

FrameFeed OpenBagFeed(const std::filesystem::path& path, const BagFeedOptions& options) {
  BagSourceOptions source_options;
  source_options.image_topic = options.image_topic;
  source_options.camera_info_topic = options.camera_info_topic;
  source_options.camera_path = options.camera_path;
  auto bag = std::make_shared<const BagImageSource>(BagImageSource::Open(path, source_options));
  FrameFeed frames;
  frames.layout = "rosbag";
  frames.camera = bag->camera();
  frames.size = bag->size();
  frames.timestamp_s = [bag](std::size_t i) { return bag->timestamp_s(i); };
  frames.load_image = [bag](std::size_t i) { return bag->LoadImage(i); };
  return frames;
}

#else

FrameFeed OpenBagFeed(const std::filesystem::path& path, const BagFeedOptions& options) {
  throw InputError(path.string(),
                   "this arucoslam was built without ROS 1, so it cannot read bags (install "
                   "the ROS packages of scripts/install-deps.sh and build again)");
}

#endif

}  // namespace arucoslam
