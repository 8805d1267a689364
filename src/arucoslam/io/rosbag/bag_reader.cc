#include "arucoslam/io/rosbag/bag_reader.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <optional>
#include <set>
#include <utility>

#include "arucoslam/io/calibration.h"
#include "arucoslam/io/rosbag/camera_info.h"
#include "arucoslam/io/rosbag/image_messages.h"
#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

constexpr const char* kImageType = "sensor_msgs/Image";
constexpr const char* kCompressedImageType = "sensor_msgs/CompressedImage";
constexpr const char* kCameraInfoType = "sensor_msgs/CameraInfo";

// Topics of the bag whose messages are of one of `types`, sorted.
std::vector<std::string> TopicsOfType(const rosbag::Bag& bag,
                                      const std::vector<std::string>& types) {
  rosbag::View view(bag);
  std::set<std::string> topics;
  for (const rosbag::ConnectionInfo* connection : view.getConnections()) {
    if (std::find(types.begin(), types.end(), connection->datatype) != types.end()) {
      topics.insert(connection->topic);
    }
  }
  return {topics.begin(), topics.end()};
}

std::string ListOrNone(const std::vector<std::string>& topics) {
  return topics.empty() ? std::string("none") : fmt::format("{}", fmt::join(topics, ", "));
}

std::int64_t StampNs(const ros::Time& stamp) {
  return static_cast<std::int64_t>(stamp.sec) * 1000000000 + stamp.nsec;
}

double MedianRateHz(const std::vector<std::int64_t>& stamps_ns) {
  if (stamps_ns.size() < 2) return 0.0;
  std::vector<std::int64_t> steps;
  for (std::size_t i = 1; i < stamps_ns.size(); ++i) steps.push_back(stamps_ns[i] - stamps_ns[i - 1]);
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const std::int64_t median = steps[steps.size() / 2];
  return median > 0 ? 1e9 / static_cast<double>(median) : 0.0;
}

}  // namespace

struct BagImageSource::Impl {
  std::filesystem::path path;
  std::string image_topic;
  std::string source;  // "<bag>: <topic>" for errors
  rosbag::Bag bag;
  std::vector<rosbag::MessageInstance> messages;
  std::vector<std::int64_t> stamps_ns;
  CameraModel camera;

  // The header stamp of an image message (throws through rosbag on a corrupt record).
  std::int64_t Stamp(const rosbag::MessageInstance& message) const {
    if (message.getDataType() == kImageType) {
      return StampNs(message.instantiate<sensor_msgs::Image>()->header.stamp);
    }
    return StampNs(message.instantiate<sensor_msgs::CompressedImage>()->header.stamp);
  }
  CameraModel ReadCamera(const BagSourceOptions& options) const;
  cv::Mat Decode(std::size_t index) const;
};

CameraModel BagImageSource::Impl::ReadCamera(const BagSourceOptions& options) const {
  if (!options.camera_path.empty()) return ReadCameraModel(options.camera_path);
  const std::string topic = options.camera_info_topic.empty()
                                ? CameraInfoTopicFor(image_topic)
                                : options.camera_info_topic;
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& message : view) {
    const auto info = message.instantiate<sensor_msgs::CameraInfo>();
    if (!info) break;  // the topic holds another type: reported below
    return CameraFromInfo(*info, path.string() + ": " + topic);
  }
  throw InputError(path.string(),
                   fmt::format("no sensor_msgs/CameraInfo on topic '{}' (camera_info topics in "
                               "the bag: {}); give --camera-info-topic or --camera FILE",
                               topic, ListOrNone(TopicsOfType(bag, {kCameraInfoType}))));
}

cv::Mat BagImageSource::Impl::Decode(std::size_t index) const {
  const rosbag::MessageInstance& message = messages.at(index);
  const std::string where = fmt::format("{}: image {}", source, index);
  cv::Mat grey;
  try {
    if (message.getDataType() == kImageType) {
      grey = GreyFromImage(*message.instantiate<sensor_msgs::Image>(), where);
    } else {
      grey = GreyFromCompressedImage(*message.instantiate<sensor_msgs::CompressedImage>(), where);
    }
  } catch (const rosbag::BagException& error) {
    throw InputError(where, std::string("unreadable message: ") + error.what());
  } catch (const ros::Exception& error) {
    throw InputError(where, std::string("unreadable message: ") + error.what());
  }
  if (grey.cols != camera.width || grey.rows != camera.height) {
    throw InputError(where, fmt::format("image is {}x{}, the camera's {}x{}", grey.cols,
                                        grey.rows, camera.width, camera.height));
  }
  return grey;
}

std::string CameraInfoTopicFor(const std::string& image_topic) {
  const std::size_t slash = image_topic.find_last_of('/');
  if (slash == std::string::npos) return "camera_info";
  return image_topic.substr(0, slash) + "/camera_info";
}

bool IsBagPath(const std::filesystem::path& path) {
  std::error_code error;
  return path.extension() == ".bag" && std::filesystem::is_regular_file(path, error);
}

BagImageSource BagImageSource::Open(const std::filesystem::path& path,
                                    const BagSourceOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->image_topic = options.image_topic;
  impl->source = path.string() + ": " + options.image_topic;
  try {
    impl->bag.open(path.string(), rosbag::bagmode::Read);
    const std::vector<std::string> image_topics =
        TopicsOfType(impl->bag, {kImageType, kCompressedImageType});
    if (!options.Check()) {
      throw InputError(path.string(), fmt::format("a bag needs --image-topic (image topics in "
                                                  "the bag: {})", ListOrNone(image_topics)));
    }
    if (std::find(image_topics.begin(), image_topics.end(), options.image_topic) ==
        image_topics.end()) {
      throw InputError(path.string(),
                       fmt::format("no image topic '{}' (image topics in the bag: {})",
                                   options.image_topic, ListOrNone(image_topics)));
    }
    rosbag::View view(impl->bag, rosbag::TopicQuery(options.image_topic));
    for (const rosbag::MessageInstance& message : view) {
      const std::int64_t stamp = impl->Stamp(message);
      if (!impl->stamps_ns.empty() && stamp <= impl->stamps_ns.back()) {
        throw InputError(impl->source,
                         fmt::format("image {} has stamp {} ns, not after the previous one ({} "
                                     "ns)", impl->messages.size(), stamp, impl->stamps_ns.back()));
      }
      impl->messages.push_back(message);
      impl->stamps_ns.push_back(stamp);
    }
    impl->camera = impl->ReadCamera(options);
  } catch (const rosbag::BagException& error) {
    throw InputError(path.string(), std::string("not a readable ROS 1 bag: ") + error.what());
  } catch (const ros::Exception& error) {
    throw InputError(path.string(), std::string("corrupt message in the bag: ") + error.what());
  }
  if (impl->camera.rate_hz == 0.0) impl->camera.rate_hz = MedianRateHz(impl->stamps_ns);
  impl->Decode(0);  // the first image: readable and of the camera's size
  return BagImageSource(std::move(impl));
}

BagImageSource::BagImageSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BagImageSource::BagImageSource(BagImageSource&&) noexcept = default;
BagImageSource& BagImageSource::operator=(BagImageSource&&) noexcept = default;
BagImageSource::~BagImageSource() = default;

const std::filesystem::path& BagImageSource::path() const { return impl_->path; }
const std::string& BagImageSource::image_topic() const { return impl_->image_topic; }
const CameraModel& BagImageSource::camera() const { return impl_->camera; }
std::size_t BagImageSource::size() const { return impl_->messages.size(); }
std::int64_t BagImageSource::timestamp_ns(std::size_t index) const {
  return impl_->stamps_ns.at(index);
}
double BagImageSource::timestamp_s(std::size_t index) const {
  return 1e-9 * static_cast<double>(impl_->stamps_ns.at(index));
}
cv::Mat BagImageSource::LoadImage(std::size_t index) const { return impl_->Decode(index); }

}  // namespace arucoslam
