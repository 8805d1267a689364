#include "arucoslam/io/video_source.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <system_error>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {
namespace fs = std::filesystem;

fs::path TestDir() {
  static const fs::path dir = [] {
    const fs::path path =
        fs::temp_directory_path() / ("arucoslam_video_source_test_" + std::to_string(getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
    return path;
  }();
  return dir;
}

// Removes TestDir() after the last test.
class RemoveTestDir : public testing::Environment {
 public:
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(TestDir(), ignored);
  }
};
const testing::Environment* const kRemoveTestDir =
    testing::AddGlobalTestEnvironment(new RemoveTestDir);

CameraModel SmallCamera() { return PinholeCamera(96, 64, 80.0); }

// Frame i: a grey level ramp shifted by 3 i pixels, with a bright square, so frames differ.
cv::Mat TestFrame(int i) {
  cv::Mat frame(64, 96, CV_8UC3);
  for (int v = 0; v < frame.rows; ++v) {
    for (int u = 0; u < frame.cols; ++u) {
      const auto level = static_cast<std::uint8_t>((2 * u + v + 3 * i) % 256);
      frame.at<cv::Vec3b>(v, u) = cv::Vec3b(level, level, level);
    }
  }
  cv::rectangle(frame, cv::Rect(10 + 2 * i, 20, 12, 12), cv::Scalar::all(255), cv::FILLED);
  return frame;
}

// Writes `count` frames losslessly (FFV1 in Matroska) at `fps`.
fs::path WriteVideo(const std::string& name, int count, double fps) {
  const fs::path path = TestDir() / name;
  cv::VideoWriter writer(path.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'),
                         fps, cv::Size(96, 64), true);
  EXPECT_TRUE(writer.isOpened()) << "FFV1 in .mkv not available from OpenCV's FFmpeg";
  for (int i = 0; i < count; ++i) writer.write(TestFrame(i));
  return path;
}

TEST(VideoSourceTest, ReadsEveryFrameLosslesslyWithContainerTimestamps) {
  const fs::path path = WriteVideo("twelve.mkv", 12, 25.0);
  VideoSource source(path, SmallCamera());
  EXPECT_EQ(source.layout(), "video");
  EXPECT_FALSE(source.live());
  int count = 0;
  while (std::optional<SourceFrame> frame = source.Next()) {
    EXPECT_EQ(frame->index, static_cast<std::size_t>(count));
    EXPECT_NEAR(frame->timestamp_s, count / 25.0, 1e-3) << "frame " << count;
    ASSERT_EQ(frame->image.type(), CV_8UC1);
    cv::Mat expected;
    cv::cvtColor(TestFrame(count), expected, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::norm(frame->image, expected, cv::NORM_INF), 0.0) << "frame " << count;
    ++count;
  }
  EXPECT_EQ(count, 12);
  EXPECT_FALSE(source.Next().has_value());  // stays at the end
}

TEST(VideoSourceTest, RateReplacesTheContainerTimestamps) {
  const fs::path path = WriteVideo("rate.mkv", 5, 25.0);
  VideoSourceOptions options;
  options.rate_hz = 10.0;
  VideoSource source(path, SmallCamera(), options);
  for (int i = 0; i < 5; ++i) {
    const std::optional<SourceFrame> frame = source.Next();
    ASSERT_TRUE(frame);
    EXPECT_DOUBLE_EQ(frame->timestamp_s, i / 10.0);
  }
}

void ExpectInputError(const std::function<void()>& open, const std::string& source,
                      const std::string& message_part) {
  try {
    open();
    ADD_FAILURE() << "no InputError, expected '" << message_part << "'";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), source);
    EXPECT_NE(error.message().find(message_part), std::string::npos) << error.message();
  }
}

TEST(VideoSourceTest, BadVideosAreOneClearInputError) {
  const fs::path missing = TestDir() / "missing.mkv";
  ExpectInputError([&] { VideoSource source(missing, SmallCamera()); }, missing.string(),
                   "does not exist");
  const fs::path text = TestDir() / "text.mkv";
  WriteTextFileAtomically(text, "this is not a video\n");
  ExpectInputError([&] { VideoSource source(text, SmallCamera()); }, text.string(),
                   "cannot open the video");
  // A real video cut short after its header: no frame decodes.
  const std::string bytes = ReadTextFile(WriteVideo("whole.mkv", 4, 25.0));
  const fs::path truncated = TestDir() / "truncated.mkv";
  WriteTextFileAtomically(truncated, bytes.substr(0, 300));
  ExpectInputError([&] { VideoSource source(truncated, SmallCamera()); }, truncated.string(),
                   "video");
  const fs::path other_size = WriteVideo("size.mkv", 2, 25.0);
  ExpectInputError([&] { VideoSource source(other_size, PinholeCamera(640, 480, 500.0)); },
                   other_size.string(), "frame 0 is 96x64 but the camera calibration says 640x480");
}

}  // namespace
}  // namespace arucoslam
