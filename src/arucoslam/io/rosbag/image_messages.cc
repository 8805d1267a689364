#include "arucoslam/io/rosbag/image_messages.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

struct EncodingLayout {
  int cv_type;     // OpenCV type of one row's pixels as stored
  int conversion;  // cv::cvtColor code to grey, -1: none
};

bool LayoutOf(const std::string& encoding, EncodingLayout* layout) {
  if (encoding == "mono8" || encoding == "8UC1") {
    *layout = {CV_8UC1, -1};
  } else if (encoding == "bgr8" || encoding == "8UC3") {
    *layout = {CV_8UC3, cv::COLOR_BGR2GRAY};
  } else if (encoding == "rgb8") {
    *layout = {CV_8UC3, cv::COLOR_RGB2GRAY};
  } else if (encoding == "bgra8" || encoding == "8UC4") {
    *layout = {CV_8UC4, cv::COLOR_BGRA2GRAY};
  } else if (encoding == "rgba8") {
    *layout = {CV_8UC4, cv::COLOR_RGBA2GRAY};
  } else if (encoding == "mono16" || encoding == "16UC1") {
    *layout = {CV_16UC1, -1};
  } else {
    return false;
  }
  return true;
}

}  // namespace

cv::Mat GreyFromImage(const sensor_msgs::Image& image, const std::string& source) {
  EncodingLayout layout{};
  if (!LayoutOf(image.encoding, &layout)) {
    throw InputError(source, "image encoding '" + image.encoding +
                                 "' not supported (expected mono8, bgr8, rgb8, bgra8, rgba8 "
                                 "or mono16)");
  }
  const std::size_t row_bytes = static_cast<std::size_t>(image.width) * CV_ELEM_SIZE(layout.cv_type);
  if (image.width == 0 || image.height == 0 || image.step < row_bytes ||
      image.data.size() < static_cast<std::size_t>(image.step) * image.height) {
    throw InputError(source, "image of " + std::to_string(image.width) + "x" +
                                 std::to_string(image.height) + " " + image.encoding +
                                 " pixels with step " + std::to_string(image.step) + " holds " +
                                 std::to_string(image.data.size()) + " bytes: inconsistent");
  }
  if (layout.cv_type == CV_16UC1 && image.is_bigendian) {
    throw InputError(source, "big-endian 16-bit images are not supported");
  }
  // A view of the message's bytes; the conversions below copy.
  const cv::Mat pixels(static_cast<int>(image.height), static_cast<int>(image.width),
                       layout.cv_type, const_cast<std::uint8_t*>(image.data.data()), image.step);
  cv::Mat grey;
  if (layout.cv_type == CV_16UC1) {
    pixels.convertTo(grey, CV_8UC1, 1.0 / 256.0);
  } else if (layout.conversion >= 0) {
    cv::cvtColor(pixels, grey, layout.conversion);
  } else {
    grey = pixels.clone();
  }
  return grey;
}

cv::Mat GreyFromCompressedImage(const sensor_msgs::CompressedImage& image,
                                const std::string& source) {
  cv::Mat grey;
  if (!image.data.empty()) {
    const cv::Mat bytes(1, static_cast<int>(image.data.size()), CV_8UC1,
                        const_cast<std::uint8_t*>(image.data.data()));
    grey = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  }
  if (grey.empty()) {
    throw InputError(source, "compressed image (format '" + image.format + "', " +
                                 std::to_string(image.data.size()) +
                                 " bytes) could not be decoded");
  }
  return grey;
}

sensor_msgs::Image ImageMessageFromGrey(const cv::Mat& grey) {
  CV_Assert(grey.type() == CV_8UC1);
  sensor_msgs::Image image;
  image.height = static_cast<std::uint32_t>(grey.rows);
  image.width = static_cast<std::uint32_t>(grey.cols);
  image.encoding = "mono8";
  image.is_bigendian = 0;
  image.step = image.width;
  image.data.resize(static_cast<std::size_t>(image.step) * image.height);
  for (int row = 0; row < grey.rows; ++row) {
    const std::uint8_t* begin = grey.ptr<std::uint8_t>(row);
    std::copy(begin, begin + grey.cols, image.data.begin() + row * image.step);
  }
  return image;
}

}  // namespace arucoslam
