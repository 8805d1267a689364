// BagImageSource: the grey images of one image topic of a ROS 1 bag (sensor_msgs/Image or
// sensor_msgs/CompressedImage) in time order with their header stamps, and the camera from a
// sensor_msgs/CameraInfo topic of the bag or from a calibration file. No ROS type appears
// here: `run` and the tests use it like a Dataset.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct BagSourceOptions {
  std::string image_topic;  // required
  // Empty: the image topic's namespace + "/camera_info" (ROS's convention).
  std::string camera_info_topic;
  // Calibration file (any format of io/calibration.h); when given it is used instead of the
  // bag's camera_info, which may then be absent.
  std::filesystem::path camera_path;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Require(!image_topic.empty(), "image_topic", "non-empty");
    return check.ok();
  }
};

// The default camera_info topic of an image topic: "/cam/image_raw" -> "/cam/camera_info".
std::string CameraInfoTopicFor(const std::string& image_topic);

// True for a path to an existing regular file named *.bag.
bool IsBagPath(const std::filesystem::path& path);

class BagImageSource {
 public:
  // Opens the bag, indexes the image topic's messages and reads the camera; decodes the first
  // image to check its size against the camera. Throws InputError naming the bag (and topic):
  // unreadable or corrupt bag, image topic absent (the message lists the bag's image topics)
  // or empty, camera_info topic absent with no camera_path (lists the CameraInfo topics),
  // bad camera_info, image stamps going back in time, an image that cannot be decoded or
  // whose size differs from the camera's.
  static BagImageSource Open(const std::filesystem::path& path, const BagSourceOptions& options);

  BagImageSource(BagImageSource&&) noexcept;
  BagImageSource& operator=(BagImageSource&&) noexcept;
  ~BagImageSource();

  const std::filesystem::path& path() const;
  const std::string& image_topic() const;
  // The camera; its rate_hz is the images' median rate when the calibration file gives none.
  const CameraModel& camera() const;
  std::size_t size() const;
  std::int64_t timestamp_ns(std::size_t index) const;  // header stamp of image `index`
  double timestamp_s(std::size_t index) const;
  // Image `index` as CV_8UC1. Throws InputError (bag, topic, message index) when the message
  // cannot be read or decoded, or its size differs from the camera's.
  cv::Mat LoadImage(std::size_t index) const;

 private:
  struct Impl;
  explicit BagImageSource(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace arucoslam
