#include "arucoslam/io/image_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

class ImageFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    image_ = cv::Mat(48, 64, CV_8UC1);
    cv::randu(image_, 0, 255);  // incompressible: the IDAT chunk is most of the file
    ASSERT_TRUE(cv::imwrite((folder_ / "frame.png").string(), image_));
    png_ = ReadTextFile(folder_ / "frame.png");
  }

  fs::path Write(const std::string& name, const std::string& bytes) {
    const fs::path path = folder_ / name;
    WriteTextFileAtomically(path, bytes);
    return path;
  }
  // The InputError message ReadImageFile gives for `path` ("" when it reads the image).
  static std::string ErrorOf(const fs::path& path) {
    try {
      ReadImageFile(path, cv::IMREAD_GRAYSCALE);
    } catch (const InputError& error) {
      EXPECT_EQ(error.source(), path.string());
      return error.message();
    }
    return "";
  }

  ScratchFolder scratch_{"image_file_test"};
  const fs::path& folder_ = scratch_.path();
  cv::Mat image_;
  std::string png_;
};

TEST_F(ImageFileTest, AWholePngReadsBackItsPixels) {
  EXPECT_FALSE(PngLayoutDefect(png_).has_value());
  const cv::Mat read = ReadImageFile(folder_ / "frame.png", cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(read.size(), image_.size());
  EXPECT_EQ(cv::countNonZero(read != image_), 0);
}

TEST_F(ImageFileTest, ATruncatedPngIsNamedAsSuchWithoutTheDecodersOwnMessages) {
  // Cut inside the IDAT chunk, inside the last chunk header, and just before IEND's end.
  for (const std::size_t keep : {png_.size() / 2, png_.size() - 8, std::size_t{20}}) {
    const std::string cut = png_.substr(0, keep);
    const fs::path path = Write("cut.png", cut);
    ::testing::internal::CaptureStderr();
    const std::string message = ErrorOf(path);
    const std::string printed = ::testing::internal::GetCapturedStderr();
    EXPECT_NE(message.find("truncated PNG"), std::string::npos) << keep << ": " << message;
    EXPECT_EQ(printed, "") << keep;
  }
  // Everything up to IEND but IEND itself.
  const std::string no_end = png_.substr(0, png_.size() - 12);
  EXPECT_EQ(ErrorOf(Write("no_end.png", no_end)), "truncated PNG (no IEND chunk)");
}

TEST_F(ImageFileTest, MissingFilesAndFilesThatAreNoImageAreNamed) {
  EXPECT_EQ(ErrorOf(folder_ / "absent.png"), "image not found");
  EXPECT_EQ(ErrorOf(folder_), "is not a file (an image was expected)");
  const std::string text = "not an image\n";
  EXPECT_EQ(ErrorOf(Write("notes.png", text)), "cannot read the image (not an image or corrupt)");
  EXPECT_EQ(ErrorOf(Write("empty.png", {})), "cannot read the image (not an image or corrupt)");
  EXPECT_FALSE(PngLayoutDefect(text).has_value());  // not a PNG at all
}

TEST_F(ImageFileTest, AJpegCutShortIsNamedAsSuchWithoutTheDecodersWarning) {
  ASSERT_TRUE(cv::imwrite((folder_ / "frame.jpg").string(), image_));
  const std::string jpeg = ReadTextFile(folder_ / "frame.jpg");
  EXPECT_FALSE(JpegLayoutDefect(jpeg).has_value());
  EXPECT_EQ(ReadImageFile(folder_ / "frame.jpg", cv::IMREAD_GRAYSCALE).size(), image_.size());
  const std::string cut = jpeg.substr(0, jpeg.size() / 2);
  const fs::path path = Write("cut.jpg", cut);
  ::testing::internal::CaptureStderr();
  const std::string message = ErrorOf(path);
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(message, "truncated JPEG (no end-of-image marker)");
}

TEST_F(ImageFileTest, OtherFormatsAreLeftToTheDecoder) {
  ASSERT_TRUE(cv::imwrite((folder_ / "frame.bmp").string(), image_));
  const cv::Mat read = ReadImageFile(folder_ / "frame.bmp", cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(cv::countNonZero(read != image_), 0);
}

}  // namespace
}  // namespace arucoslam
