#include "arucoslam/exe/bag_feed.h"

#include <utility>

#include "arucoslam/util/error.h"
#ifdef ARUCOSLAM_WITH_ROS
#include "arucoslam/io/rosbag/bag_reader.h"
#endif

namespace arucoslam {

bool IsBagDataset(const std::filesystem::path& path) { return path.extension() == ".bag"; }

#ifdef ARUCOSLAM_WITH_ROS

namespace {

// The images of one bag topic, decoded one at a time as Next() asks.
class BagFrameSource : public FrameSource {
 public:
  explicit BagFrameSource(BagImageSource bag) : bag_(std::move(bag)) {}

  std::optional<SourceFrame> Next() override {
    if (next_ >= bag_.size()) return std::nullopt;
    SourceFrame frame;
    frame.index = next_;
    frame.timestamp_s = bag_.timestamp_s(next_);
    frame.image = bag_.LoadImage(next_);
    ++next_;
    return frame;
  }
  const CameraModel& camera() const override { return bag_.camera(); }
  std::string layout() const override { return "rosbag"; }
  std::optional<std::size_t> size() const override { return bag_.size(); }

 private:
  BagImageSource bag_;
  std::size_t next_ = 0;
};

}  // namespace

std::unique_ptr<FrameSource> OpenBagSource(const std::filesystem::path& path,
                                           const BagFeedOptions& options) {
  BagSourceOptions source_options;
  source_options.image_topic = options.image_topic;
  source_options.camera_info_topic = options.camera_info_topic;
  source_options.camera_path = options.camera_path;
  return std::make_unique<BagFrameSource>(BagImageSource::Open(path, source_options));
}

#else

std::unique_ptr<FrameSource> OpenBagSource(const std::filesystem::path& path,
                                           const BagFeedOptions& options) {
  throw InputError(path.string(),
                   "this arucoslam was built without ROS 1, so it cannot read bags (install "
                   "the ROS packages of scripts/install-deps.sh and build again)");
}

#endif

}  // namespace arucoslam
