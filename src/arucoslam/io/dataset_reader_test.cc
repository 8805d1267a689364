#include "arucoslam/io/dataset_reader.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>

#include "arucoslam/io/calibration.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {
namespace fs = std::filesystem;

const fs::path kMicro = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "euroc_v101_micro";

void WriteText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

// Runs `fn`, expects an InputError whose source contains `source_part` and whose message
// contains `message_part`.
void ExpectInputError(const std::function<void()>& fn, const std::string& source_part,
                      const std::string& message_part) {
  try {
    fn();
    ADD_FAILURE() << "no InputError; expected '" << message_part << "'";
  } catch (const InputError& error) {
    EXPECT_NE(error.source().find(source_part), std::string::npos) << error.what();
    EXPECT_NE(error.message().find(message_part), std::string::npos) << error.what();
  }
}

CameraModel SmallCamera() {
  CameraModel camera;
  camera.width = 64;
  camera.height = 48;
  camera.fx = camera.fy = 50.0;
  camera.cx = 31.5;
  camera.cy = 23.5;
  camera.rate_hz = 10.0;
  return camera;
}

class DatasetReaderTest : public ::testing::Test {
 protected:
  // A EuRoC sequence of `n` 64x48 frames, 100 ms apart, with the small camera.
  fs::path MakeEuroc(int n) {
    const fs::path cam = folder_ / "seq" / "mav0" / "cam0";
    fs::create_directories(cam / "data");
    WriteEuRoCSensorYaml(SmallCamera(), cam / "sensor.yaml");
    std::string csv = "#timestamp [ns],filename\n";
    for (int i = 0; i < n; ++i) {
      const std::string stamp = std::to_string(1000000000LL + i * 100000000LL);
      csv += stamp + "," + stamp + ".png\n";
      cv::imwrite((cam / "data" / (stamp + ".png")).string(),
                  cv::Mat(48, 64, CV_8U, cv::Scalar(i)));
    }
    WriteText(cam / "data.csv", csv);
    return folder_ / "seq";
  }

  ScratchFolder scratch_{"dataset_test"};
  const fs::path& folder_ = scratch_.path();
};

TEST_F(DatasetReaderTest, EurocMicroRealSequence) {
  if (!fs::exists(kMicro)) GTEST_SKIP() << "test data folder missing: " << kMicro;
  const Dataset dataset = Dataset::Open(kMicro);
  EXPECT_EQ(dataset.layout(), DatasetLayout::kEuroc);
  ASSERT_EQ(dataset.size(), 95u);
  EXPECT_EQ(dataset.frame(0).timestamp_ns, 1403715273262142976LL);
  EXPECT_EQ(dataset.frame(94).timestamp_ns, 1403715277962142976LL);
  EXPECT_NEAR(dataset.frame(1).timestamp_s - dataset.frame(0).timestamp_s, 0.05, 1e-6);
  const CameraModel& camera = dataset.camera();
  EXPECT_EQ(camera.width, 752);
  EXPECT_EQ(camera.height, 480);
  EXPECT_DOUBLE_EQ(camera.fx, 458.654);
  EXPECT_DOUBLE_EQ(camera.cy, 248.375);
  EXPECT_EQ(camera.model, DistortionModel::kRadTan);
  EXPECT_DOUBLE_EQ(camera.distortion[0], -0.28340811);
  const cv::Mat image = dataset.LoadImage(94);
  EXPECT_EQ(image.type(), CV_8UC1);
  EXPECT_EQ(image.cols, 752);
  EXPECT_EQ(image.rows, 480);
  EXPECT_FALSE(dataset.markers_path().has_value());

  // Ground truth: body poses x T_BS must equal the world_from_cam0 rows of the README's
  // reference file (within 2e-5 m, as the README states; rotation within 1e-4 rad).
  ASSERT_TRUE(dataset.has_ground_truth());
  ASSERT_EQ(dataset.ground_truth().size(), 74u);
  const Trajectory reference = ReadEurocTrajectory(kMicro / "gt_cam0_for_these_frames.csv");
  ASSERT_EQ(reference.size(), 74u);
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const Rigid3& ours = dataset.ground_truth().poses[i];
    EXPECT_NEAR(dataset.ground_truth().timestamps[i], reference.timestamps[i], 1e-6);
    EXPECT_LT((ours.translation - reference.poses[i].translation).norm(), 2e-5) << i;
    EXPECT_LT(RotationAngle(ours.rotation.conjugate() * reference.poses[i].rotation), 1e-4) << i;
  }
}

TEST_F(DatasetReaderTest, EurocSyntheticSequenceAndCameraOverride) {
  const fs::path seq = MakeEuroc(3);
  Dataset dataset = Dataset::Open(seq);
  ASSERT_EQ(dataset.size(), 3u);
  EXPECT_EQ(dataset.frame(2).timestamp_ns, 1200000000LL);
  EXPECT_NEAR(dataset.frame(2).timestamp_s, 1.2, 1e-12);
  EXPECT_EQ(dataset.LoadImage(2).at<std::uint8_t>(10, 10), 2);
  EXPECT_FALSE(dataset.has_ground_truth());
  WriteText(seq / "markers.json", "{}");
  EXPECT_EQ(dataset.markers_path(), seq / "markers.json");
  // A camera file of another size overrides sensor.yaml, and then the images disagree.
  CameraModel other = SmallCamera();
  other.width = 752;
  WriteEuRoCSensorYaml(other, folder_ / "other.yaml");
  DatasetOptions options;
  options.camera_path = folder_ / "other.yaml";
  ExpectInputError([&] { Dataset::Open(seq, options); }, ".png",
                   "image is 64x48 but the camera calibration says 752x48");
}

TEST_F(DatasetReaderTest, EurocErrorsNameFileAndLine) {
  ExpectInputError([&] { Dataset::Open(folder_ / "nowhere"); }, "nowhere", "");
  const fs::path seq = MakeEuroc(3);
  const fs::path csv = seq / "mav0" / "cam0" / "data.csv";
  const std::string good = "#timestamp [ns],filename\n1000000000,1000000000.png\n";

  WriteText(csv, good + "1100000000;1100000000.png\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "data.csv", "line 3: expected");
  WriteText(csv, good + "11000x0000,1100000000.png\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "data.csv", "line 3: expected");
  WriteText(csv, good + "1100000000,\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "data.csv", "line 3: expected");
  WriteText(csv, good + "1100000000,missing.png\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "data.csv", "line 3: image");
  WriteText(csv, good + "900000000,1100000000.png\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "data.csv", "line 3: timestamp 900000000");
  WriteText(csv, "#timestamp [ns],filename\n\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "seq", "no frames");

  // Unreadable image (not a PNG), wrong resolution.
  WriteText(csv, good);
  WriteText(seq / "mav0" / "cam0" / "data" / "1000000000.png", "not a png");
  ExpectInputError([&] { Dataset::Open(seq); }, "1000000000.png", "cannot read");
  cv::imwrite((seq / "mav0" / "cam0" / "data" / "1000000000.png").string(),
              cv::Mat(480, 640, CV_8U, cv::Scalar(0)));
  ExpectInputError([&] { Dataset::Open(seq); }, "1000000000.png",
                   "image is 640x480 but the camera calibration says 64x48");

  fs::remove(csv);
  ExpectInputError([&] { Dataset::Open(seq); }, "data.csv", "");
  fs::remove(seq / "mav0" / "cam0" / "sensor.yaml");
  WriteText(csv, good);
  ExpectInputError([&] { Dataset::Open(seq); }, "sensor.yaml", "");
}

TEST_F(DatasetReaderTest, TumRgbdFolder) {
  const fs::path seq = folder_ / "tum";
  fs::create_directories(seq / "rgb");
  for (int i = 0; i < 2; ++i) {
    cv::imwrite((seq / "rgb" / (std::to_string(i) + ".png")).string(),
                cv::Mat(48, 64, CV_8UC3, cv::Scalar(10, 20, 30)));
  }
  WriteText(seq / "rgb.txt",
            "# color images\n# timestamp filename\n1305031102.175304 rgb/0.png\n"
            "1305031102.211214 rgb/1.png\n");
  WriteText(seq / "groundtruth.txt",
            "# timestamp tx ty tz qx qy qz qw\n1305031102.1758 1 2 3 0 0 0 1\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "tum",
                   "the TUM RGB-D layout needs a camera calibration file (--camera)");
  WriteEuRoCSensorYaml(SmallCamera(), folder_ / "camera.yaml");
  DatasetOptions options;
  options.camera_path = folder_ / "camera.yaml";
  const Dataset dataset = Dataset::Open(seq, options);
  EXPECT_EQ(dataset.layout(), DatasetLayout::kTumRgbd);
  ASSERT_EQ(dataset.size(), 2u);
  EXPECT_DOUBLE_EQ(dataset.frame(1).timestamp_s, 1305031102.211214);
  EXPECT_EQ(dataset.frame(1).timestamp_ns, 1305031102211214000LL);
  const cv::Mat grey = dataset.LoadImage(0);
  EXPECT_EQ(grey.type(), CV_8UC1);
  ASSERT_EQ(dataset.ground_truth().size(), 1u);
  EXPECT_EQ(dataset.ground_truth().poses[0].translation, Eigen::Vector3d(1, 2, 3));

  WriteText(seq / "rgb.txt", "1305031102.175304 rgb/0.png extra\n");
  ExpectInputError([&] { Dataset::Open(seq, options); }, "rgb.txt", "line 1: expected");
}

TEST_F(DatasetReaderTest, ImageFolderSortedWithRate) {
  const fs::path seq = folder_ / "images";
  fs::create_directories(seq);
  for (const char* name : {"b.png", "a.png", "c.jpg"}) {
    cv::imwrite((seq / name).string(), cv::Mat(48, 64, CV_8U, cv::Scalar(0)));
  }
  WriteText(seq / "notes.txt", "not an image");
  ExpectInputError([&] { Dataset::Open(seq); }, "images",
                   "the image-folder layout needs a camera calibration file (--camera)");
  WriteEuRoCSensorYaml(SmallCamera(), folder_ / "camera.yaml");
  DatasetOptions options;
  options.camera_path = folder_ / "camera.yaml";
  Dataset dataset = Dataset::Open(seq, options);  // the camera's rate: 10 Hz
  EXPECT_EQ(dataset.layout(), DatasetLayout::kImageFolder);
  ASSERT_EQ(dataset.size(), 3u);
  EXPECT_EQ(dataset.frame(0).image_path.filename(), "a.png");
  EXPECT_EQ(dataset.frame(2).image_path.filename(), "c.jpg");
  EXPECT_NEAR(dataset.frame(2).timestamp_s, 0.2, 1e-12);
  options.rate_hz = 40.0;
  dataset = Dataset::Open(seq, options);
  EXPECT_NEAR(dataset.frame(2).timestamp_s, 0.05, 1e-12);

  const fs::path empty = folder_ / "empty";
  fs::create_directories(empty);
  ExpectInputError([&] { Dataset::Open(empty, options); }, "empty", "no frames");
  ExpectInputError([&] { Dataset::Open(empty, options); }, "empty", "no known sequence layout");
}

const fs::path kKitti07 = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "kitti07_first160";

TEST_F(DatasetReaderTest, KittiOdometryRealClip) {
  if (!fs::exists(kKitti07)) GTEST_SKIP() << "test data folder missing: " << kKitti07;
  const Dataset dataset = Dataset::Open(kKitti07 / "original");
  EXPECT_EQ(dataset.layout(), DatasetLayout::kKitti);
  ASSERT_EQ(dataset.size(), 160u);
  const CameraModel& camera = dataset.camera();
  EXPECT_EQ(camera.width, 1226);
  EXPECT_EQ(camera.height, 370);
  EXPECT_EQ(camera.fx, 707.0912);
  EXPECT_EQ(camera.fy, 707.0912);
  EXPECT_EQ(camera.cx, 601.8873);
  EXPECT_EQ(camera.cy, 183.1104);
  EXPECT_EQ(camera.model, DistortionModel::kNone);
  EXPECT_EQ(dataset.frame(0).timestamp_s, 0.0);
  EXPECT_EQ(dataset.frame(1).timestamp_s, 0.1038752);
  EXPECT_EQ(dataset.frame(159).image_path.filename(), "000159.png");
  EXPECT_FALSE(dataset.has_ground_truth());  // no poses/07.txt two folders up
  EXPECT_EQ(dataset.LoadImage(159).cols, 1226);

  DatasetOptions options;
  options.ground_truth_path = kKitti07 / "poses_07_first160_kitti.txt";
  const Dataset with_truth = Dataset::Open(kKitti07 / "original", options);
  ASSERT_EQ(with_truth.ground_truth().size(), 160u);
  EXPECT_EQ(with_truth.ground_truth().timestamps[1], 0.1038752);
  EXPECT_TRUE(with_truth.ground_truth().poses[0].translation.isZero(1e-9));
  // The clip's TUM copy of the same poses (timestamps offset by 1e9 s).
  const Trajectory tum = ReadTumTrajectory(kKitti07 / "groundtruth_first160_tum.txt");
  ASSERT_EQ(tum.size(), 160u);
  EXPECT_LT((with_truth.ground_truth().poses[159].translation - tum.poses[159].translation).norm(),
            1e-5);
}

// A KITTI folder of the standard layout (sequences/NN beside poses/NN.txt) with the colour
// camera: P2's translation puts camera 2 beside camera 0 in the ground truth.
TEST_F(DatasetReaderTest, KittiStandardLayoutColourCameraAndErrors) {
  const fs::path seq = folder_ / "dataset" / "sequences" / "04";
  fs::create_directories(seq / "image_2");
  for (int i = 0; i < 3; ++i) {
    cv::imwrite((seq / "image_2" / fmt::format("{:06d}.png", i)).string(),
                cv::Mat(48, 64, CV_8UC3, cv::Scalar(i, 2 * i, 3 * i)));
  }
  WriteText(seq / "times.txt", "0.000000e+00\n1.000000e-01\n2.000000e-01\n3.000000e-01\n");
  const std::string p0 = "5.0e+01 0 3.15e+01 0 0 5.0e+01 2.35e+01 0 0 0 1 0";
  // Camera 2 sits 0.06 m left of camera 0: t = (0.06, 0, 0), P2[3] = fx * 0.06 = 3.
  WriteText(seq / "calib.txt", "P0: " + p0 + "\nP1: " + p0 +
                                   "\nP2: 5.0e+01 0 3.15e+01 3 0 "
                                   "5.0e+01 2.35e+01 0 0 0 1 0\nP3: " +
                                   p0 + "\nTr: " + p0 + "\n");
  WriteText(folder_ / "dataset" / "poses" / "04.txt",
            "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n1 0 0 0 0 1 0 0 0 0 1 2\n");
  const Dataset dataset = Dataset::Open(seq);
  EXPECT_EQ(dataset.layout(), DatasetLayout::kKitti);
  ASSERT_EQ(dataset.size(), 3u);
  EXPECT_EQ(dataset.camera().width, 64);
  EXPECT_EQ(dataset.camera().cx, 31.5);
  EXPECT_DOUBLE_EQ(dataset.frame(2).timestamp_s, 0.2);
  ASSERT_EQ(dataset.ground_truth().size(), 3u);
  EXPECT_TRUE(dataset.ground_truth().poses[1].translation.isApprox(Eigen::Vector3d(-0.06, 0, 1)))
      << dataset.ground_truth().poses[1].translation.transpose();

  WriteText(seq / "times.txt", "0.0\n0.1\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "times.txt",
                   "2 lines, but image 000002.png needs line 3");
  WriteText(seq / "times.txt", "0.0\nsoon\n0.2\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "times.txt", "line 2: expected a time in seconds");
  WriteText(seq / "times.txt", "0.0\n0.1\n0.2\n");
  WriteText(seq / "calib.txt", "P0: " + p0 + "\nP2: 5.0e+01 0 3.15e+01 3 0 5.0e+01 2.35e+01\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "calib.txt",
                   "line 2: P2: expected 12 numbers, found 7");
  WriteText(seq / "calib.txt", "P0: " + p0 + "\n");
  ExpectInputError([&] { Dataset::Open(seq); }, "calib.txt", "P2: missing");
  fs::remove(seq / "calib.txt");
  ExpectInputError([&] { Dataset::Open(seq); }, "calib.txt", "does not exist");
  // --camera replaces calib.txt.
  WriteEuRoCSensorYaml(SmallCamera(), folder_ / "camera.yaml");
  DatasetOptions options;
  options.camera_path = folder_ / "camera.yaml";
  EXPECT_EQ(Dataset::Open(seq, options).camera().fx, 50.0);
  cv::imwrite((seq / "image_2" / "frame.png").string(), cv::Mat(48, 64, CV_8UC3));
  ExpectInputError([&] { Dataset::Open(seq, options); }, "frame.png", "KITTI frame number");
}

}  // namespace
}  // namespace arucoslam
