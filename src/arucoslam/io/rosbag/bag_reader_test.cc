#include "arucoslam/io/rosbag/bag_reader.h"

#include <gtest/gtest.h>
#include <rosbag/bag.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "arucoslam/io/calibration.h"
#include "arucoslam/io/rosbag/camera_info.h"
#include "arucoslam/io/rosbag/image_messages.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

cv::Mat Pattern(int index) {
  cv::Mat grey(24, 32, CV_8UC1);
  cv::RNG random(static_cast<std::uint64_t>(index) + 1);  // the same pixels for an index
  random.fill(grey, cv::RNG::UNIFORM, cv::Scalar(index), cv::Scalar(200 + index));
  return grey;
}

class BagReaderTest : public ::testing::Test {
 protected:
  void SetUp() override { camera_ = PinholeCamera(32, 24, 30.0); }

  // Three raw mono8 images at 0.1 s steps on /cam/image_raw, three PNG-compressed ones on
  // /cam/image_raw/compressed, camera_info on /cam/camera_info unless `with_info` is false.
  fs::path WriteBag(bool with_info = true) {
    const fs::path path = dir_ / "test.bag";
    rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
    for (int i = 0; i < 3; ++i) {
      const ros::Time stamp(100, 100000000 * static_cast<std::uint32_t>(i) + 7);
      sensor_msgs::Image image = ImageMessageFromGrey(Pattern(i));
      image.header.stamp = stamp;
      bag.write("/cam/image_raw", stamp, image);
      sensor_msgs::CompressedImage compressed;
      compressed.header.stamp = stamp;
      compressed.format = "png";
      cv::imencode(".png", Pattern(i), compressed.data);
      bag.write("/cam/image_raw/compressed", stamp, compressed);
      if (with_info) {
        sensor_msgs::CameraInfo info = CameraInfoFromModel(camera_);
        info.header.stamp = stamp;
        bag.write("/cam/camera_info", stamp, info);
      }
    }
    return path;
  }

  ScratchFolder scratch_{"bag_reader_test"};
  const fs::path& dir_ = scratch_.path();
  CameraModel camera_;
};

TEST_F(BagReaderTest, RawAndCompressedTopicsGiveTheSameImagesAndStamps) {
  const fs::path path = WriteBag();
  for (const std::string topic : {"/cam/image_raw", "/cam/image_raw/compressed"}) {
    BagSourceOptions options;
    options.image_topic = topic;
    options.camera_info_topic = "/cam/camera_info";
    const BagImageSource source = BagImageSource::Open(path, options);
    ASSERT_EQ(source.size(), 3u) << topic;
    EXPECT_EQ(source.camera().width, 32);
    EXPECT_EQ(source.camera().fx, 30.0);
    EXPECT_NEAR(source.camera().rate_hz, 10.0, 1e-9);
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(source.timestamp_ns(i), 100000000000LL + 100000000LL * i + 7);
      EXPECT_EQ(cv::norm(source.LoadImage(i), Pattern(static_cast<int>(i)), cv::NORM_INF), 0.0);
    }
  }
}

TEST_F(BagReaderTest, CameraInfoTopicDefaultsToTheImageNamespace) {
  EXPECT_EQ(CameraInfoTopicFor("/cam/image_raw"), "/cam/camera_info");
  EXPECT_EQ(CameraInfoTopicFor("image"), "camera_info");
  BagSourceOptions options;
  options.image_topic = "/cam/image_raw";
  EXPECT_EQ(BagImageSource::Open(WriteBag(), options).camera().fx, 30.0);
}

TEST_F(BagReaderTest, UnknownTopicListsTheImageTopics) {
  BagSourceOptions options;
  options.image_topic = "/camera/image";
  try {
    BagImageSource::Open(WriteBag(), options);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), (dir_ / "test.bag").string());
    EXPECT_NE(error.message().find("/cam/image_raw, /cam/image_raw/compressed"), std::string::npos)
        << error.what();
  }
}

TEST_F(BagReaderTest, MissingCameraInfoNeedsACameraFile) {
  const fs::path path = WriteBag(/*with_info=*/false);
  BagSourceOptions options;
  options.image_topic = "/cam/image_raw";
  try {
    BagImageSource::Open(path, options);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(error.message().find("/cam/camera_info"), std::string::npos) << error.what();
    EXPECT_NE(error.message().find("--camera"), std::string::npos) << error.what();
  }
  options.camera_path = dir_ / "camera.yaml";
  WriteEuRoCSensorYaml(camera_, options.camera_path);
  EXPECT_EQ(BagImageSource::Open(path, options).size(), 3u);
  camera_.width = 64;  // a camera of another size than the images
  WriteEuRoCSensorYaml(camera_, options.camera_path);
  EXPECT_THROW(BagImageSource::Open(path, options), InputError);
}

TEST_F(BagReaderTest, CorruptOrTruncatedBagsAreInputErrors) {
  const fs::path path = WriteBag();
  BagSourceOptions options;
  options.image_topic = "/cam/image_raw";
  std::ofstream(dir_ / "text.bag") << "not a bag at all\n";
  EXPECT_THROW(BagImageSource::Open(dir_ / "text.bag", options), InputError);
  const std::uintmax_t size = fs::file_size(path);
  fs::resize_file(path, size / 2);  // the index at the end is lost
  EXPECT_THROW(BagImageSource::Open(path, options), InputError);
  EXPECT_THROW(BagImageSource::Open(dir_ / "absent.bag", options), InputError);
}

TEST_F(BagReaderTest, IsBagPathNeedsAnExistingBagFile) {
  const fs::path path = WriteBag();
  EXPECT_TRUE(IsBagPath(path));
  EXPECT_FALSE(IsBagPath(dir_ / "absent.bag"));
  EXPECT_FALSE(IsBagPath(dir_));
}

}  // namespace
}  // namespace arucoslam
