// Grey images from ROS 1 image messages (sensor_msgs/Image raw mono8/bgr8/rgb8/bgra8/rgba8/
// mono16, sensor_msgs/CompressedImage JPEG/PNG), as the SLAM takes them: 8-bit, one channel.
#pragma once

#include <opencv2/core.hpp>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <string>

namespace arucoslam {

// A copy of the message's pixels as CV_8UC1 (colour converted with OpenCV's weights, mono16
// scaled by 1/256). Throws InputError naming `source` (bag and topic, or the topic) for an
// unsupported encoding, a step or data size that does not match the image's size, or
// big-endian 16-bit data.
cv::Mat GreyFromImage(const sensor_msgs::Image& image, const std::string& source);

// Decodes the message's JPEG or PNG data to CV_8UC1. Throws InputError naming `source` when
// OpenCV cannot decode it.
cv::Mat GreyFromCompressedImage(const sensor_msgs::CompressedImage& image,
                                const std::string& source);

// A mono8 message of a CV_8UC1 image (tests, bag writing).
sensor_msgs::Image ImageMessageFromGrey(const cv::Mat& grey);

}  // namespace arucoslam
