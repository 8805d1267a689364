#include "arucoslam/io/rosbag/image_messages.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

cv::Mat Gradient(int width, int height) {
  cv::Mat grey(height, width, CV_8UC1);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) grey.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(r * 16 + c);
  }
  return grey;
}

TEST(ImageMessagesTest, Mono8RoundTripsWithPaddedRows) {
  const cv::Mat grey = Gradient(5, 4);
  sensor_msgs::Image message = ImageMessageFromGrey(grey);
  EXPECT_EQ(message.encoding, "mono8");
  EXPECT_EQ(cv::norm(GreyFromImage(message, "t"), grey, cv::NORM_INF), 0.0);
  // The same pixels with 3 bytes of padding per row.
  message.step = 8;
  message.data.assign(8 * 4, 0);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 5; ++c) message.data[r * 8 + c] = grey.at<std::uint8_t>(r, c);
  }
  EXPECT_EQ(cv::norm(GreyFromImage(message, "t"), grey, cv::NORM_INF), 0.0);
}

TEST(ImageMessagesTest, ColourIsConvertedWithTheChannelOrderOfItsEncoding) {
  cv::Mat bgr(2, 3, CV_8UC3, cv::Scalar(10, 100, 200));  // B G R
  sensor_msgs::Image message;
  message.width = 3;
  message.height = 2;
  message.step = 9;
  message.encoding = "bgr8";
  message.data.assign(bgr.data, bgr.data + 18);
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  EXPECT_EQ(cv::norm(GreyFromImage(message, "t"), expected, cv::NORM_INF), 0.0);
  message.encoding = "rgb8";  // the same bytes read as R G B give another grey
  cv::cvtColor(bgr, expected, cv::COLOR_RGB2GRAY);
  EXPECT_EQ(cv::norm(GreyFromImage(message, "t"), expected, cv::NORM_INF), 0.0);
}

TEST(ImageMessagesTest, Mono16IsScaledToEightBits) {
  sensor_msgs::Image message;
  message.width = 2;
  message.height = 1;
  message.step = 4;
  message.encoding = "mono16";
  const std::uint16_t pixels[2] = {256 * 3, 65535};
  message.data.resize(4);
  std::memcpy(message.data.data(), pixels, 4);
  const cv::Mat grey = GreyFromImage(message, "t");
  EXPECT_EQ(grey.at<std::uint8_t>(0, 0), 3);
  EXPECT_EQ(grey.at<std::uint8_t>(0, 1), 255);
}

TEST(ImageMessagesTest, BadMessagesNameTheSource) {
  sensor_msgs::Image message = ImageMessageFromGrey(Gradient(5, 4));
  message.encoding = "bayer_rggb8";
  try {
    GreyFromImage(message, "x.bag: /cam/image");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "x.bag: /cam/image");
    EXPECT_NE(error.message().find("bayer_rggb8"), std::string::npos);
  }
  message.encoding = "mono8";
  message.data.resize(7);  // fewer bytes than step x height
  EXPECT_THROW(GreyFromImage(message, "t"), InputError);
  sensor_msgs::CompressedImage compressed;
  compressed.format = "jpeg";
  compressed.data = {1, 2, 3};
  EXPECT_THROW(GreyFromCompressedImage(compressed, "t"), InputError);
}

TEST(ImageMessagesTest, CompressedPngDecodesExactly) {
  const cv::Mat grey = Gradient(7, 5);
  sensor_msgs::CompressedImage compressed;
  compressed.format = "mono8; png compressed ";
  cv::imencode(".png", grey, compressed.data);
  EXPECT_EQ(cv::norm(GreyFromCompressedImage(compressed, "t"), grey, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace arucoslam
