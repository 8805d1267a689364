#include "arucoslam/io/camera_source.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <opencv2/videoio.hpp>
#include <string>
#include <thread>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {
namespace fs = std::filesystem;

// A video file stands in for the camera: cv::VideoCapture reads it as fast as it decodes, like
// a camera delivering frames whether or not they are asked for.
fs::path WriteVideo(int count) {
  const fs::path path = fs::temp_directory_path() /
                        ("arucoslam_camera_source_test_" + std::to_string(getpid()) + ".mkv");
  cv::VideoWriter writer(path.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'),
                         30.0, cv::Size(64, 48), false);
  EXPECT_TRUE(writer.isOpened());
  for (int i = 0; i < count; ++i) writer.write(cv::Mat(48, 64, CV_8UC1, cv::Scalar(i % 256)));
  return path;
}

TEST(CameraSourceTest, SlowConsumerGetsFewFramesAndTheRestAreCounted) {
  const fs::path video = WriteVideo(200);
  CameraSourceOptions options;
  options.queue_capacity = 2;
  CameraSource source(video.string(), PinholeCamera(64, 48, 50.0), options);
  EXPECT_TRUE(source.live());
  EXPECT_EQ(source.layout(), "camera");
  std::size_t handed_out = 0;
  double previous = -1.0;
  while (std::optional<SourceFrame> frame = source.Next()) {
    EXPECT_EQ(frame->index, handed_out);
    EXPECT_GT(frame->timestamp_s, previous);
    EXPECT_EQ(frame->image.type(), CV_8UC1);
    previous = frame->timestamp_s;
    ++handed_out;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // a busy SLAM
  }
  EXPECT_EQ(source.frames_captured(), 200u);
  EXPECT_EQ(handed_out + source.frames_dropped(), 200u);
  EXPECT_GT(source.frames_dropped(), 100u);  // decoding is far faster than 50 frames/s
  fs::remove(video);
}

TEST(CameraSourceTest, StopFlagEndsCaptureAndHeldFramesAreHandedOut) {
  const fs::path video = WriteVideo(5000);
  std::atomic<bool> stop{false};
  CameraSourceOptions options;
  options.stop = &stop;
  options.queue_capacity = 3;
  CameraSource source(video.string(), PinholeCamera(64, 48, 50.0), options);
  ASSERT_TRUE(source.Next().has_value());
  stop = true;  // as the SIGINT handler does
  std::size_t after_stop = 0;
  while (source.Next()) ++after_stop;
  EXPECT_LE(after_stop, 3u);  // at most what the queue held
  EXPECT_LT(source.frames_captured(), 5000u);
  fs::remove(video);
}

TEST(CameraSourceTest, DestructorStopsACaptureNobodyReads) {
  const fs::path video = WriteVideo(3000);
  {
    CameraSource source(video.string(), PinholeCamera(64, 48, 50.0));
  }  // must join promptly, not wait for the stream to end
  fs::remove(video);
}

TEST(CameraSourceTest, BadDevicesAreOneClearInputError) {
  try {
    CameraSource source("/dev/video_arucoslam_missing", PinholeCamera(64, 48, 50.0));
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "/dev/video_arucoslam_missing");
    EXPECT_NE(error.message().find("cannot open the camera"), std::string::npos);
  }
  const fs::path video = WriteVideo(3);
  try {
    CameraSource source(video.string(), PinholeCamera(640, 480, 500.0));
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.message(), "frames are 64x48 but the camera calibration says 640x480");
  }
  fs::remove(video);
}

}  // namespace
}  // namespace arucoslam
