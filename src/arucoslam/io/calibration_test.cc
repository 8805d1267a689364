#include "arucoslam/io/calibration.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <ostream>
#include <string>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

const fs::path kDataDir = ARUCOSLAM_TEST_DATA_DIR;

fs::path TempDir() {
  static const fs::path dir = [] {
    const fs::path path =
        fs::temp_directory_path() / ("arucoslam_calibration_test_" + std::to_string(getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
    return path;
  }();
  return dir;
}

// Removes the temporary folder after the last test.
class TempDirCleanup : public testing::Environment {
 public:
  void TearDown() override { fs::remove_all(TempDir()); }
};
const testing::Environment* const kCleanup = testing::AddGlobalTestEnvironment(new TempDirCleanup);

fs::path WriteFile(const std::string& name, const std::string& text) {
  const fs::path path = TempDir() / name;
  WriteTextFileAtomically(path, text);
  return path;
}

// Skips the test when a real data set is not installed.
#define REQUIRE_DATA(relative)                                                 \
  if (!fs::exists(kDataDir / (relative))) {                                    \
    GTEST_SKIP() << "test data missing: " << (kDataDir / (relative)).string(); \
  }

// EuRoC MAV cam0 (V1_01 sensor.yaml), which several of the files below describe.
void ExpectEurocCam0Intrinsics(const CameraModel& camera) {
  EXPECT_EQ(camera.width, 752);
  EXPECT_EQ(camera.height, 480);
  EXPECT_EQ(camera.fx, 458.654);
  EXPECT_EQ(camera.fy, 457.296);
  EXPECT_EQ(camera.cx, 367.215);
  EXPECT_EQ(camera.cy, 248.375);
}

void ExpectEurocCam0(const CameraModel& camera) {
  ExpectEurocCam0Intrinsics(camera);
  EXPECT_EQ(camera.model, DistortionModel::kRadTan);
  const std::array<double, kMaxDistortionCoefficients> expected = {-0.28340811, 0.07395907,
                                                                   0.00019359, 1.76187114e-05, 0.0};
  EXPECT_EQ(camera.distortion, expected);
  EXPECT_TRUE(camera.Check());
}

TEST(CalibrationTest, ReadsTheRealEuRoCSensorYaml) {
  REQUIRE_DATA("euroc_v101_micro/mav0/cam0/sensor.yaml");
  const CameraCalibration calibration =
      ReadCameraCalibration(kDataDir / "euroc_v101_micro/mav0/cam0/sensor.yaml");
  const CameraModel& camera = calibration.camera;
  EXPECT_EQ(calibration.format, CalibrationFormat::kEuRoC);
  ExpectEurocCam0(camera);
  EXPECT_EQ(camera.rate_hz, 20.0);
  // T_BS: body_from_cam, first row 0.0148655429818, -0.999880929698, 0.00414029679422.
  EXPECT_TRUE(calibration.body_from_cam.translation.isApprox(
      Eigen::Vector3d(-0.0216401454975, -0.064676986768, 0.00981073058949), 1e-12));
  const Eigen::Matrix3d r = calibration.body_from_cam.RotationMatrix();
  EXPECT_NEAR(r(0, 0), 0.0148655429818, 1e-6);
  EXPECT_NEAR(r(0, 1), -0.999880929698, 1e-6);
  EXPECT_NEAR(r(2, 2), 0.999660727178, 1e-6);
}

TEST(CalibrationTest, ReadsTheRealFlatRosCameraInfoFiles) {
  REQUIRE_DATA("fiducials_aruco_unit/camera_test_images.yaml");
  const CameraCalibration test_images =
      ReadCameraCalibration(kDataDir / "fiducials_aruco_unit/camera_test_images.yaml");
  EXPECT_EQ(test_images.format, CalibrationFormat::kRosCameraInfo);
  const CameraModel& camera = test_images.camera;
  EXPECT_EQ(camera.width, 1280);
  EXPECT_EQ(camera.height, 960);
  EXPECT_EQ(camera.fx, 1006.12628575);
  EXPECT_EQ(camera.fy, 1004.01543301);
  EXPECT_EQ(camera.cx, 655.863924415);
  EXPECT_EQ(camera.cy, 490.614022124);
  EXPECT_EQ(camera.model, DistortionModel::kRadTan);
  const std::array<double, kMaxDistortionCoefficients> expected = {
      0.134973508728, -0.233586982745, 0.000669703031508, 0.00484673746587, 0.0};
  EXPECT_EQ(camera.distortion, expected);

  const CameraModel bag =
      ReadCameraModel(kDataDir / "fiducials_aruco_unit/camera_aruco_images_bag.yaml");
  EXPECT_EQ(bag.fx, 1014.34310338);
  EXPECT_EQ(bag.cy, 469.566377991);
  EXPECT_EQ(bag.distortion[2], -5.60164774256e-05);
}

TEST(CalibrationTest, ReadsStandardRosCameraInfo) {
  const fs::path path = WriteFile("ros_plumb_bob.yaml", R"(image_width: 640
image_height: 480
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [612.5, 0, 320.25, 0, 611.75, 240.5, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0.1, -0.2, 0.001, -0.002, 0.05]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
)");
  const CameraModel camera = ReadCameraModel(path);
  EXPECT_EQ(camera.width, 640);
  EXPECT_EQ(camera.fx, 612.5);
  EXPECT_EQ(camera.fy, 611.75);
  EXPECT_EQ(camera.cx, 320.25);
  EXPECT_EQ(camera.cy, 240.5);
  EXPECT_EQ(camera.model, DistortionModel::kRadTan);
  EXPECT_EQ(camera.distortion[4], 0.05);

  const fs::path fisheye = WriteFile("ros_equidistant.yaml", R"(image_width: 512
image_height: 512
camera_matrix: {rows: 3, cols: 3, data: [190.5, 0, 254.5, 0, 190.25, 256.5, 0, 0, 1]}
distortion_model: equidistant
distortion_coefficients: {rows: 1, cols: 4, data: [0.0035, 0.0007, -0.002, 0.0002]}
)");
  const CameraModel fisheye_camera = ReadCameraModel(fisheye);
  EXPECT_EQ(fisheye_camera.model, DistortionModel::kEquidistant);
  EXPECT_EQ(fisheye_camera.distortion[3], 0.0002);
}

TEST(CalibrationTest, ReadsTheRealOpenCvRational8Files) {
  REQUIRE_DATA("photonvision_charuco_lifecam/camera_opencv.yaml");
  const std::array<double, kMaxDistortionCoefficients> expected = {
      0.16442580388260605, -0.9866244487633755, 0.003472548710624201, -0.002772366031203418,
      1.8909532518418533,  0.04108971525533507, 0.06374355932009733,  -0.0679460705265192};
  // The OpenCV FileStorage file and the sensor.yaml derived from it give the same camera.
  for (const char* file : {"camera_opencv.yaml", "euroc/mav0/cam0/sensor.yaml"}) {
    const CameraCalibration calibration =
        ReadCameraCalibration(kDataDir / "photonvision_charuco_lifecam" / file);
    const CameraModel& camera = calibration.camera;
    EXPECT_EQ(calibration.format,
              file[0] == 'c' ? CalibrationFormat::kOpenCv : CalibrationFormat::kEuRoC);
    EXPECT_EQ(camera.width, 1280);
    EXPECT_EQ(camera.height, 720);
    EXPECT_EQ(camera.fx, 1144.0265829623002);
    EXPECT_EQ(camera.fy, 1142.1874735882805);
    EXPECT_EQ(camera.cx, 604.8583376755885);
    EXPECT_EQ(camera.cy, 343.69882696120504);
    EXPECT_EQ(camera.model, DistortionModel::kRational) << file;
    EXPECT_EQ(camera.distortion, expected) << file;
    EXPECT_TRUE(camera.Check());
  }
}

// A camera of each of OpenCV's pinhole models, written by cv::FileStorage as YAML and as XML
// (what OpenCV's calibration sample writes), reads back equal.
TEST(CalibrationTest, ReadsOpenCvFileStorageYamlAndXml) {
  const std::vector<double> all = {-0.28, 0.07,  0.0002, 0.00002, 0.01,   0.02, -0.03,
                                   0.04,  0.001, -0.002, 0.003,   0.0005, 0.01, -0.02};
  for (const std::size_t count : {0, 4, 5, 8, 12, 14}) {
    for (const char* extension : {".yaml", ".xml"}) {
      const fs::path path =
          TempDir() / ("opencv_" + std::to_string(count) + std::string(extension));
      {
        cv::FileStorage storage(path.string(), cv::FileStorage::WRITE);
        storage << "image_width" << 752 << "image_height" << 480;
        storage << "camera_matrix"
                << cv::Mat(
                       cv::Matx33d(458.654, 0.0, 367.215, 0.0, 457.296, 248.375, 0.0, 0.0, 1.0));
        storage << "distortion_coefficients"
                << cv::Mat(std::vector<double>(all.begin(), all.begin() + count), true);
        storage << "avg_reprojection_error" << 0.25;
      }
      const CameraCalibration calibration = ReadCameraCalibration(path);
      SCOPED_TRACE(path.string());
      EXPECT_EQ(calibration.format, CalibrationFormat::kOpenCv);
      const CameraModel& camera = calibration.camera;
      ExpectEurocCam0Intrinsics(camera);
      const DistortionModel expected_model = count == 0    ? DistortionModel::kNone
                                             : count <= 5  ? DistortionModel::kRadTan
                                             : count == 8  ? DistortionModel::kRational
                                             : count == 12 ? DistortionModel::kThinPrism
                                                           : DistortionModel::kTilted;
      EXPECT_EQ(camera.model, expected_model);
      for (std::size_t i = 0; i < kMaxDistortionCoefficients; ++i) {
        EXPECT_EQ(camera.distortion[i], i < count ? all[i] : 0.0) << i;
      }
      EXPECT_TRUE(camera.Check());
    }
  }
}

TEST(CalibrationTest, ReadsKalibrCamchain) {
  const fs::path path = WriteFile("camchain.yaml", R"(cam0:
  T_cam_imu:
  - [0.0148655429818, 0.999557249008, -0.0257744366974, 0.0652229509055]
  - [-0.999880929698, 0.0149672133247, 0.00375618835797, -0.0207064249118]
  - [0.00414029679422, 0.0257155299480, 0.999660727178, -0.0080546303257]
  - [0.0, 0.0, 0.0, 1.0]
  cam_overlaps: [1]
  camera_model: pinhole
  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
  distortion_model: radtan
  intrinsics: [458.654, 457.296, 367.215, 248.375]
  resolution: [752, 480]
  rostopic: /cam0/image_raw
  timeshift_cam_imu: 0.0
cam1:
  camera_model: pinhole
  distortion_model: equidistant
)");
  const CameraCalibration calibration = ReadCameraCalibration(path);
  EXPECT_EQ(calibration.format, CalibrationFormat::kKalibr);
  ExpectEurocCam0(calibration.camera);
  // body (IMU) from camera is the inverse of T_cam_imu: EuRoC's T_BS.
  EXPECT_TRUE(calibration.body_from_cam.translation.isApprox(
      Eigen::Vector3d(-0.0216401454975, -0.064676986768, 0.00981073058949), 1e-6));
  EXPECT_NEAR(calibration.body_from_cam.RotationMatrix()(0, 1), -0.999880929698, 1e-9);

  const fs::path fisheye = WriteFile("camchain_fisheye.yaml", R"(cam0:
  camera_model: pinhole
  distortion_coeffs: [0.0035, 0.0007, -0.002, 0.0002]
  distortion_model: equidistant
  intrinsics: [190.5, 190.25, 254.5, 256.5]
  resolution: [512, 512]
)");
  const CameraCalibration fisheye_calibration = ReadCameraCalibration(fisheye);
  EXPECT_EQ(fisheye_calibration.camera.model, DistortionModel::kEquidistant);
  EXPECT_EQ(fisheye_calibration.camera.distortion[3], 0.0002);
  EXPECT_TRUE(fisheye_calibration.body_from_cam.ToMatrix().isIdentity());
}

// ORB-SLAM3's older settings layout (as its EuRoC.yaml), with the OpenCV directive line.
TEST(CalibrationTest, ReadsOrbSlam3PinHoleSettings) {
  const fs::path path = WriteFile("orbslam3_euroc.yaml", R"(%YAML:1.0
---
Camera.type: "PinHole"
Camera.fx: 458.654
Camera.fy: 457.296
Camera.cx: 367.215
Camera.cy: 248.375
Camera.k1: -0.28340811
Camera.k2: 0.07395907
Camera.p1: 0.00019359
Camera.p2: 1.76187114e-05
Camera.width: 752
Camera.height: 480
Camera.fps: 20
Camera.RGB: 1
ORBextractor.nFeatures: 1000
)");
  const CameraCalibration calibration = ReadCameraCalibration(path);
  EXPECT_EQ(calibration.format, CalibrationFormat::kOrbSlam3);
  ExpectEurocCam0(calibration.camera);
  EXPECT_EQ(calibration.camera.rate_hz, 20.0);
}

// The File.version "1.0" layout with a fisheye and an IMU extrinsic (!!opencv-matrix).
TEST(CalibrationTest, ReadsOrbSlam3Version1KannalaBrandtSettings) {
  const fs::path path = WriteFile("orbslam3_tumvi.yaml", R"(%YAML:1.0
File.version: "1.0"
Camera.type: "KannalaBrandt8"
Camera1.fx: 190.97847715128717
Camera1.fy: 190.9733070521226
Camera1.cx: 254.93170605935475
Camera1.cy: 256.8974428996504
Camera1.k1: 0.0034823894022493434
Camera1.k2: 0.0007150348452162257
Camera1.k3: -0.0020532361418706202
Camera1.k4: 0.00020293673591811182
Camera.width: 512
Camera.height: 512
Camera.fps: 20
IMU.T_b_c1: !!opencv-matrix
   rows: 4
   cols: 4
   dt: f
   data: [0, -1, 0, 0.05,
          1, 0, 0, -0.01,
          0, 0, 1, 0.02,
          0, 0, 0, 1]
)");
  const CameraCalibration calibration = ReadCameraCalibration(path);
  const CameraModel& camera = calibration.camera;
  EXPECT_EQ(camera.model, DistortionModel::kEquidistant);
  EXPECT_EQ(camera.fx, 190.97847715128717);
  EXPECT_EQ(camera.distortion[3], 0.00020293673591811182);
  EXPECT_EQ(camera.distortion[4], 0.0);
  EXPECT_EQ(camera.height, 512);
  EXPECT_TRUE(calibration.body_from_cam.translation.isApprox(Eigen::Vector3d(0.05, -0.01, 0.02)));
  EXPECT_TRUE((calibration.body_from_cam * Eigen::Vector3d::UnitX())
                  .isApprox(Eigen::Vector3d(0.05, 0.99, 0.02), 1e-12));
}

TEST(CalibrationTest, WrittenSensorYamlReadsBackEqual) {
  CameraModel radtan;
  radtan.width = 752;
  radtan.height = 480;
  radtan.fx = 458.654;
  radtan.fy = 457.296;
  radtan.cx = 367.215;
  radtan.cy = 248.375;
  radtan.model = DistortionModel::kRadTan;
  radtan.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0};
  radtan.rate_hz = 20.0;
  CameraModel radtan_k3 = radtan;
  radtan_k3.distortion[4] = 0.1 / 3.0;  // not short in decimal
  radtan_k3.fx = 1.0 / 3.0 * 1000.0;
  CameraModel fisheye = radtan;
  fisheye.model = DistortionModel::kEquidistant;
  fisheye.distortion = {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202,
                        0.00020293673591811182, 0.0};
  CameraModel pinhole = radtan;
  pinhole.model = DistortionModel::kNone;
  pinhole.distortion = {};
  pinhole.rate_hz = 0.0;
  CameraModel rational = radtan;
  rational.model = DistortionModel::kRational;
  rational.distortion = {0.16442580388260605,   -0.9866244487633755, 0.003472548710624201,
                         -0.002772366031203418, 1.8909532518418533,  0.04108971525533507,
                         0.06374355932009733,   -0.0679460705265192};
  CameraModel thin_prism = rational;
  thin_prism.model = DistortionModel::kThinPrism;
  thin_prism.distortion[8] = 0.004;
  thin_prism.distortion[11] = -1.0 / 3000.0;
  CameraModel tilted = thin_prism;
  tilted.model = DistortionModel::kTilted;
  tilted.distortion[12] = 0.03;
  tilted.distortion[13] = -0.05;
  const Rigid3 body_from_cam(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(0.1, -0.2, 0.3));
  int index = 0;
  for (const CameraModel& camera :
       {radtan, radtan_k3, fisheye, pinhole, rational, thin_prism, tilted}) {
    const fs::path path = TempDir() / ("written_" + std::to_string(index++)) / "sensor.yaml";
    fs::create_directories(path.parent_path());
    WriteEuRoCSensorYaml(camera, path, body_from_cam);
    const CameraCalibration back = ReadCameraCalibration(path);
    EXPECT_EQ(back.format, CalibrationFormat::kEuRoC);
    EXPECT_EQ(back.camera.width, camera.width);
    EXPECT_EQ(back.camera.height, camera.height);
    EXPECT_EQ(back.camera.fx, camera.fx);
    EXPECT_EQ(back.camera.fy, camera.fy);
    EXPECT_EQ(back.camera.cx, camera.cx);
    EXPECT_EQ(back.camera.cy, camera.cy);
    EXPECT_EQ(back.camera.model, camera.model) << DistortionModelName(camera.model);
    EXPECT_EQ(back.camera.distortion, camera.distortion);
    EXPECT_EQ(back.camera.rate_hz, camera.rate_hz);
    EXPECT_TRUE(back.body_from_cam.ToMatrix().isApprox(body_from_cam.ToMatrix(), 1e-15));
  }
  CameraModel invalid = radtan;
  invalid.fx = -1.0;
  EXPECT_THROW(FormatEuRoCSensorYaml(invalid), std::invalid_argument);
}

TEST(CalibrationTest, MissingFileNamesThePath) {
  const fs::path path = TempDir() / "no_such_sensor.yaml";
  try {
    ReadCameraModel(path);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), path.string());
  }
}

// One malformed file per case: the exact message naming the field.
struct MalformedCase {
  const char* name;
  std::string text;
  std::string message;
  bool message_is_prefix = false;  // the rest is the YAML parser's own wording
};

void PrintTo(const MalformedCase& c, std::ostream* out) { *out << c.name; }

const std::string kEuRoCHead = "%YAML:1.0\nsensor_type: camera\nrate_hz: 20\n";

std::vector<MalformedCase> MalformedCases() {
  return {
      {"EuRoCMissingResolution",
       kEuRoCHead + "intrinsics: [458.6, 457.3, 367.2, 248.4]\n"
                    "distortion_model: radial-tangential\n"
                    "distortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]\n",
       "resolution: missing"},
      {"EuRoCMissingIntrinsics", kEuRoCHead + "resolution: [752, 480]\ndistortion_model: none\n",
       "intrinsics: missing"},
      {"EuRoCIntrinsicsCount",
       kEuRoCHead + "resolution: [752, 480]\nintrinsics: [458.6, 457.3, 367.2]\n"
                    "distortion_model: radial-tangential\n"
                    "distortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]\n",
       "intrinsics: expected 4 numbers, found 3"},
      {"EuRoCIntrinsicsNotANumber",
       kEuRoCHead + "resolution: [752, 480]\nintrinsics: [458.6, abc, 367.2, 248.4]\n"
                    "distortion_model: radial-tangential\n"
                    "distortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]\n",
       "intrinsics: item 2: expected a number, found 'abc'"},
      {"EuRoCUnknownDistortionModel",
       kEuRoCHead + "resolution: [752, 480]\nintrinsics: [458.6, 457.3, 367.2, 248.4]\n"
                    "distortion_model: kannala-brandt-6\n"
                    "distortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]\n",
       "distortion_model: unknown model 'kannala-brandt-6' (expected radial-tangential, "
       "equidistant, opencv_rational8, opencv_thin_prism12, opencv_tilted14 or none)"},
      {"EuRoCRationalCount",
       kEuRoCHead + "resolution: [752, 480]\nintrinsics: [458.6, 457.3, 367.2, 248.4]\n"
                    "distortion_model: opencv_rational8\n"
                    "distortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002, 0.1]\n",
       "distortion_coefficients: expected 8 numbers, found 5"},
      {"EuRoCNegativeFocalLength",
       kEuRoCHead + "resolution: [752, 480]\nintrinsics: [-458.6, 457.3, 367.2, 248.4]\n"
                    "distortion_model: radial-tangential\n"
                    "distortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]\n",
       "intrinsics: focal lengths must be positive, found fx = -458.6, fy = 457.3"},
      {"EuRoCDistortionCount",
       kEuRoCHead + "resolution: [752, 480]\nintrinsics: [458.6, 457.3, 367.2, 248.4]\n"
                    "distortion_model: equidistant\n"
                    "distortion_coefficients: [-0.28, 0.07, 0.0002]\n",
       "distortion_coefficients: expected 4 numbers, found 3"},
      {"EuRoCFractionalResolution",
       kEuRoCHead + "resolution: [752.5, 480]\nintrinsics: [458.6, 457.3, 367.2, 248.4]\n"
                    "distortion_model: none\n",
       "resolution: expected whole pixels, found 752.5"},
      {"EuRoCZeroResolution",
       kEuRoCHead + "resolution: [0, 480]\nintrinsics: [458.6, 457.3, 367.2, 248.4]\n"
                    "distortion_model: none\n",
       "resolution: width and height must be positive, found 0 x 480"},
      {"EuRoCNotRigidTBS",
       kEuRoCHead + "resolution: [752, 480]\nintrinsics: [458.6, 457.3, 367.2, 248.4]\n"
                    "distortion_model: none\n"
                    "T_BS: {rows: 4, cols: 4, data: [2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, "
                    "0, 0, 0, 1]}\n",
       "T_BS: not a rigid transform (expected an orthonormal rotation and last row 0 0 0 1)"},
      {"OrbSlamFocalNotANumber",
       "%YAML:1.0\nCamera.type: \"PinHole\"\nCamera.fx: fast\nCamera.fy: 1\nCamera.cx: 1\n"
       "Camera.cy: 1\nCamera.width: 10\nCamera.height: 10\n",
       "Camera.fx: expected a number, found 'fast'"},
      {"OrbSlamMissingWidth",
       "%YAML:1.0\nCamera.fx: 500\nCamera.fy: 500\nCamera.cx: 320\nCamera.cy: 240\n"
       "Camera.height: 480\n",
       "Camera.width: missing"},
      {"OrbSlamUnknownType",
       "%YAML:1.0\nCamera.type: \"Omni\"\nCamera.fx: 500\nCamera.fy: 500\nCamera.cx: 320\n"
       "Camera.cy: 240\nCamera.width: 640\nCamera.height: 480\n",
       "Camera.type: unknown model 'Omni' (expected PinHole, KannalaBrandt8 or Rectified)"},
      {"OrbSlamFisheyeMissingK4",
       "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \"KannalaBrandt8\"\nCamera1.fx: 190\n"
       "Camera1.fy: 190\nCamera1.cx: 254\nCamera1.cy: 256\nCamera1.k1: 0.1\nCamera1.k2: 0.01\n"
       "Camera1.k3: 0.001\nCamera.width: 512\nCamera.height: 512\n",
       "Camera1.k4: missing"},
      {"OrbSlamUnsupportedVersion", "%YAML:1.0\nFile.version: \"2.0\"\nCamera1.fx: 190\n",
       "File.version: unsupported version '2.0' (expected 1.0)"},
      {"RosSkewedCameraMatrix",
       "image_width: 640\nimage_height: 480\ncamera_matrix: {rows: 3, cols: 3, data: [500, 2, "
       "320, 0, 500, 240, 0, 0, 1]}\ndistortion_model: plumb_bob\n"
       "distortion_coefficients: {rows: 1, cols: 5, data: [0, 0, 0, 0, 0]}\n",
       "camera_matrix.data: expected [fx, 0, cx, 0, fy, cy, 0, 0, 1] (no skew)"},
      {"RosUnknownDistortionModel",
       "image_width: 640\nimage_height: 480\nK: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n"
       "distortion_model: fov\nD: [0.9]\n",
       "distortion_model: unknown model 'fov' (expected plumb_bob, rational_polynomial, "
       "equidistant or none)"},
      {"RosRationalCount",
       "image_width: 640\nimage_height: 480\nK: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n"
       "distortion_model: rational_polynomial\nD: [0.1, 0, 0, 0, 0]\n",
       "D: expected 8 numbers, found 5"},
      {"OpenCvDistortionCount",
       "%YAML:1.0\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
       "  {rows: 3, cols: 3, dt: d, data: [500, 0, 320, 0, 500, 240, 0, 0, 1]}\n"
       "distortion_coefficients: !!opencv-matrix\n  {rows: 1, cols: 6, dt: d, data: [0.1, 0, 0, "
       "0, 0, 0]}\n",
       "distortion_coefficients.data: expected 0, 4, 5, 8, 12 or 14, found 6 numbers"},
      {"OpenCvMatrixShape",
       "%YAML:1.0\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
       "  {rows: 2, cols: 3, dt: d, data: [500, 0, 320, 0, 500, 240]}\n",
       "camera_matrix: expected a 3x3 matrix"},
      {"OpenCvDataShorterThanShape",
       "%YAML:1.0\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
       "  {rows: 3, cols: 3, dt: d, data: [500, 0, 320, 0, 500, 240, 0, 0, 1]}\n"
       "distortion_coefficients: !!opencv-matrix\n  {rows: 1, cols: 5, dt: d, data: [0.1, 0]}\n",
       "distortion_coefficients.data: expected 5 numbers, found 2"},
      {"OpenCvMissingHeight",
       "%YAML:1.0\nimage_width: 640\ncamera_matrix: !!opencv-matrix\n"
       "  {rows: 3, cols: 3, dt: d, data: [500, 0, 320, 0, 500, 240, 0, 0, 1]}\n",
       "image_height: missing"},
      {"OpenCvXmlFocalNotPositive",
       "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>\n"
       "<image_height>480</image_height>\n<camera_matrix type_id=\"opencv-matrix\"><rows>3</rows>"
       "<cols>3</cols><dt>d</dt><data>0. 0. 320. 0. 500. 240. 0. 0. 1.</data></camera_matrix>\n"
       "</opencv_storage>\n",
       "camera_matrix.data: focal lengths must be positive, found fx = 0, fy = 500"},
      {"OpenCvXmlBroken",
       "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width\n",
       "not valid OpenCV XML: ", true},
      {"KalibrUnsupportedModel",
       "cam0:\n  camera_model: omni\n  intrinsics: [0.8, 300, 300, 320, 240]\n",
       "cam0.camera_model: unsupported model 'omni' (expected pinhole)"},
      {"KalibrMissingIntrinsics", "cam0:\n  camera_model: pinhole\n  resolution: [640, 480]\n",
       "cam0.intrinsics: missing"},
      {"KalibrUnknownDistortionModel",
       "cam0:\n  camera_model: pinhole\n  intrinsics: [500, 500, 320, 240]\n"
       "  resolution: [640, 480]\n  distortion_model: fov\n  distortion_coeffs: [0.9]\n",
       "cam0.distortion_model: unknown model 'fov' (expected radtan, equidistant or none)"},
      {"KalibrDistortionCount",
       "cam0:\n  camera_model: pinhole\n  intrinsics: [500, 500, 320, 240]\n"
       "  resolution: [640, 480]\n  distortion_model: radtan\n  distortion_coeffs: [0.1, 0.2]\n",
       "cam0.distortion_coeffs: expected 4 to 5 numbers, found 2"},
      {"KalibrShortMatrixRow",
       "cam0:\n  camera_model: pinhole\n  intrinsics: [500, 500, 320, 240]\n"
       "  resolution: [640, 480]\n  distortion_model: none\n  distortion_coeffs: []\n"
       "  T_cam_imu:\n  - [1, 0, 0, 0]\n  - [0, 1, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]\n",
       "cam0.T_cam_imu.1: expected 4 numbers, found 3"},
      {"RosDistortionCount",
       "image_width: 640\nimage_height: 480\nK: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n"
       "distortion_model: equidistant\n"
       "distortion_coefficients: {rows: 1, cols: 5, data: [0.1, 0, 0, 0, 0]}\n",
       "distortion_coefficients.data: expected 4 numbers, found 5"},
      {"RosWidthNotAnInteger", "image_width: wide\nimage_height: 480\n",
       "image_width: expected an integer, found 'wide'"},
      {"NotYaml", "intrinsics: [1, 2\nresolution: {\n",
       "not valid YAML: line 2, column 11: ", true},
      {"EmptyFile", "", "not a camera calibration: expected a YAML map of fields"},
      {"NotAMap", "just some text\n", "not a camera calibration: expected a YAML map of fields"},
      {"UnknownFormat", "sensor_type: imu\ngyroscope_noise_density: 1.7e-4\n",
       "not a camera calibration: expected EuRoC sensor.yaml (intrinsics), ORB-SLAM3 settings "
       "(Camera.fx or Camera1.fx), ROS camera_info or OpenCV FileStorage (image_width) or "
       "Kalibr camchain (cam0)"},
  };
}

class MalformedCalibrationTest : public testing::TestWithParam<MalformedCase> {};

TEST_P(MalformedCalibrationTest, ThrowsOneClearInputError) {
  const MalformedCase& c = GetParam();
  const fs::path path = WriteFile(std::string(c.name) + ".yaml", c.text);
  try {
    ReadCameraModel(path);
    FAIL() << "expected InputError for " << c.name;
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), path.string());
    if (c.message_is_prefix) {
      EXPECT_EQ(error.message().substr(0, c.message.size()), c.message) << error.message();
    } else {
      EXPECT_EQ(error.message(), c.message);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, MalformedCalibrationTest, testing::ValuesIn(MalformedCases()),
                         [](const testing::TestParamInfo<MalformedCase>& info) {
                           return std::string(info.param.name);
                         });

}  // namespace
}  // namespace arucoslam
