#include "arucoslam/io/frame_source.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <string>

#include "arucoslam/io/calibration.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {
namespace fs = std::filesystem;

class FrameSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    camera_path_ = dir_ / "camera.yaml";
    WriteEuRoCSensorYaml(PinholeCamera(64, 48, 50.0), camera_path_);
  }

  std::string ErrorOf(const fs::path& path, const DatasetOptions& options) {
    try {
      OpenFrameSource(path, options);
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), path.string());
      return error.message();
    }
    return "no error";
  }

  ScratchFolder scratch_{"frame_source_test"};
  const fs::path& dir_ = scratch_.path();
  fs::path camera_path_;
};

TEST_F(FrameSourceTest, FolderStreamsTheDatasetInOrder) {
  const fs::path images = dir_ / "images";
  fs::create_directories(images);
  for (int i = 0; i < 3; ++i) {
    cv::imwrite((images / (std::to_string(i) + ".png")).string(),
                cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(10 * i)));
  }
  DatasetOptions options;
  options.camera_path = camera_path_;
  options.rate_hz = 4.0;
  const std::unique_ptr<FrameSource> source = OpenFrameSource(images, options);
  EXPECT_EQ(source->layout(), "images");
  EXPECT_EQ(source->size(), 3u);
  EXPECT_FALSE(source->live());
  EXPECT_EQ(source->frames_dropped(), 0u);
  EXPECT_EQ(source->camera().width, 64);
  for (int i = 0; i < 3; ++i) {
    const std::optional<SourceFrame> frame = source->Next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->index, static_cast<std::size_t>(i));
    EXPECT_DOUBLE_EQ(frame->timestamp_s, i / 4.0);
    EXPECT_EQ(frame->image.type(), CV_8UC1);
    EXPECT_EQ(frame->image.at<std::uint8_t>(0, 0), 10 * i);
  }
  EXPECT_FALSE(source->Next().has_value());
}

TEST_F(FrameSourceTest, FileOpensAsAVideoWithItsCamera) {
  const fs::path video = dir_ / "clip.mkv";
  {
    cv::VideoWriter writer(video.string(), cv::CAP_FFMPEG,
                           cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 10.0, cv::Size(64, 48),
                           false);
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 4; ++i) writer.write(cv::Mat(48, 64, CV_8UC1, cv::Scalar(40 * i)));
  }
  EXPECT_EQ(ErrorOf(video, {}), "a video needs a camera calibration file (--camera)");
  DatasetOptions options;
  options.camera_path = camera_path_;
  const std::unique_ptr<FrameSource> source = OpenFrameSource(video, options);
  EXPECT_EQ(source->layout(), "video");
  int count = 0;
  while (const std::optional<SourceFrame> frame = source->Next()) {
    EXPECT_NEAR(frame->timestamp_s, count * 0.1, 1e-3);
    ++count;
  }
  EXPECT_EQ(count, 4);
}

TEST_F(FrameSourceTest, BadPathsAreOneClearInputError) {
  DatasetOptions options;
  options.camera_path = camera_path_;
  EXPECT_NE(ErrorOf(dir_ / "missing", options).find("does not exist"), std::string::npos);
  const fs::path empty = dir_ / "empty";
  fs::create_directories(empty);
  EXPECT_NE(ErrorOf(empty, options).find("no known sequence layout"), std::string::npos);
  const fs::path notes = dir_ / "notes.txt";
  WriteTextFileAtomically(notes, "hello\n");
  EXPECT_EQ(ErrorOf(notes, options), "cannot open the video (not a video file, or corrupt)");
}

}  // namespace
}  // namespace arucoslam
