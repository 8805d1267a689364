#include "arucoslam/geometry/camera.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <random>
#include <vector>

namespace arucoslam {
namespace {

// EuRoC MAV V1_01 cam0 (mav0/cam0/sensor.yaml): radial-tangential, 752x480.
CameraModel EurocRadTan() {
  CameraModel camera;
  camera.width = 752;
  camera.height = 480;
  camera.fx = 458.654;
  camera.fy = 457.296;
  camera.cx = 367.215;
  camera.cy = 248.375;
  camera.model = DistortionModel::kRadTan;
  camera.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0};
  return camera;
}

// The same camera with an added k3 (chosen so the distortion stays monotonic over the
// image), so the fifth coefficient is exercised too.
CameraModel RadTanWithK3() {
  CameraModel camera = EurocRadTan();
  camera.distortion[4] = 0.02;
  return camera;
}

// TUM-VI cam0 (512x512 equidistant fisheye, the published calibration).
CameraModel TumViFisheye() {
  CameraModel camera;
  camera.width = 512;
  camera.height = 512;
  camera.fx = 190.97847715128717;
  camera.fy = 190.9733070521226;
  camera.cx = 254.93170605935475;
  camera.cy = 256.8974428996504;
  camera.model = DistortionModel::kEquidistant;
  camera.distortion = {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202,
                       0.00020293673591811182, 0.0};
  return camera;
}

// PhotonVision's LifeCam HD-3000 at 1280x720: OpenCV's rational model (8 coefficients).
CameraModel LifeCamRational() {
  CameraModel camera;
  camera.width = 1280;
  camera.height = 720;
  camera.fx = 1144.0265829623002;
  camera.fy = 1142.1874735882805;
  camera.cx = 604.8583376755885;
  camera.cy = 343.69882696120504;
  camera.model = DistortionModel::kRational;
  camera.distortion = {0.16442580388260605,   -0.9866244487633755, 0.003472548710624201,
                       -0.002772366031203418, 1.8909532518418533,  0.04108971525533507,
                       0.06374355932009733,   -0.0679460705265192};
  return camera;
}

// The LifeCam with thin-prism terms (s1..s4) added.
CameraModel ThinPrism() {
  CameraModel camera = LifeCamRational();
  camera.model = DistortionModel::kThinPrism;
  camera.distortion[8] = 0.004;
  camera.distortion[9] = -0.002;
  camera.distortion[10] = 0.003;
  camera.distortion[11] = 0.001;
  return camera;
}

// The thin-prism camera on a sensor tilted by 0.03 rad about x and -0.05 rad about y.
CameraModel Tilted() {
  CameraModel camera = ThinPrism();
  camera.model = DistortionModel::kTilted;
  camera.distortion[12] = 0.03;
  camera.distortion[13] = -0.05;
  return camera;
}

// Every pinhole camera of OpenCV's family above, for tests that hold for all of them.
std::vector<CameraModel> OpenCvFamily() {
  return {EurocRadTan(), RadTanWithK3(), LifeCamRational(), ThinPrism(), Tilted()};
}

cv::Matx33d CameraMatrix(const CameraModel& camera) {
  return cv::Matx33d(camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0);
}

// Points in front of the camera whose rays make at most `max_angle` with the optical axis.
std::vector<Eigen::Vector3d> RandomPointsInCone(double max_angle, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(0.0, max_angle);
  std::uniform_real_distribution<double> azimuth(-std::numbers::pi, std::numbers::pi);
  std::uniform_real_distribution<double> depth(0.3, 20.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const double theta = angle(rng), phi = azimuth(rng), range = depth(rng);
    points.emplace_back(range * std::sin(theta) * std::cos(phi),
                        range * std::sin(theta) * std::sin(phi), range * std::cos(theta));
  }
  return points;
}

std::vector<cv::Point3d> ToCv(const std::vector<Eigen::Vector3d>& points) {
  std::vector<cv::Point3d> cv_points;
  for (const auto& p : points) cv_points.emplace_back(p.x(), p.y(), p.z());
  return cv_points;
}

// Pixels on a grid over the image, keeping those within `max_radius` px of the centre.
std::vector<Eigen::Vector2d> PixelGrid(const CameraModel& camera, double max_radius) {
  std::vector<Eigen::Vector2d> pixels;
  for (double v = 0.0; v <= camera.height - 1; v += (camera.height - 1) / 23.0) {
    for (double u = 0.0; u <= camera.width - 1; u += (camera.width - 1) / 31.0) {
      if (std::hypot(u - camera.cx, v - camera.cy) <= max_radius) pixels.emplace_back(u, v);
    }
  }
  return pixels;
}

void ExpectProjectMatchesOpenCv(const CameraModel& camera) {
  const auto points = RandomPointsInCone(0.9, 500, 7);
  std::vector<cv::Point2d> expected;
  const cv::Vec3d zero(0.0, 0.0, 0.0);
  const std::vector<double> d = camera.DistortionCoefficients();
  if (camera.model == DistortionModel::kEquidistant) {
    cv::fisheye::projectPoints(ToCv(points), expected, zero, zero, CameraMatrix(camera), d);
  } else {
    cv::projectPoints(ToCv(points), zero, zero, CameraMatrix(camera), d, expected);
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto pixel = camera.Project(points[i]);
    ASSERT_TRUE(pixel.has_value());
    EXPECT_NEAR(pixel->x(), expected[i].x, 1e-6) << "point " << points[i].transpose();
    EXPECT_NEAR(pixel->y(), expected[i].y, 1e-6) << "point " << points[i].transpose();
  }
}

TEST(CameraModelTest, OpenCvFamilyProjectMatchesOpenCvProjectPoints) {
  for (const CameraModel& camera : OpenCvFamily()) {
    SCOPED_TRACE(DistortionModelName(camera.model));
    ExpectProjectMatchesOpenCv(camera);
  }
}

TEST(CameraModelTest, EquidistantProjectMatchesOpenCvFisheyeProjectPoints) {
  ExpectProjectMatchesOpenCv(TumViFisheye());
}

TEST(CameraModelTest, NoDistortionIsThePinholeFormula) {
  CameraModel camera = EurocRadTan();
  camera.model = DistortionModel::kNone;
  camera.distortion = {};
  const Eigen::Vector3d p(0.4, -0.25, 2.0);
  const auto pixel = camera.Project(p);
  ASSERT_TRUE(pixel.has_value());
  EXPECT_NEAR(pixel->x(), 458.654 * 0.2 + 367.215, 1e-12);
  EXPECT_NEAR(pixel->y(), 457.296 * -0.125 + 248.375, 1e-12);
  EXPECT_TRUE(camera.Unproject(*pixel).isApprox(Eigen::Vector2d(0.2, -0.125), 1e-14));
}

TEST(CameraModelTest, ProjectRejectsPointsBehindTheCamera) {
  for (const CameraModel& camera : {EurocRadTan(), TumViFisheye()}) {
    EXPECT_FALSE(camera.Project(Eigen::Vector3d(0.1, 0.2, 0.0)).has_value());
    EXPECT_FALSE(camera.Project(Eigen::Vector3d(0.1, 0.2, -1.0)).has_value());
    EXPECT_TRUE(camera.Project(Eigen::Vector3d(0.1, 0.2, 1e-3)).has_value());
  }
}

TEST(CameraModelTest, OpenCvFamilyUnprojectMatchesOpenCvUndistortPoints) {
  for (const CameraModel& camera : OpenCvFamily()) {
    SCOPED_TRACE(DistortionModelName(camera.model));
    const auto pixels = PixelGrid(camera, 1e9);
    std::vector<cv::Point2d> cv_pixels, expected;
    for (const auto& pixel : pixels) cv_pixels.emplace_back(pixel.x(), pixel.y());
    const std::vector<double> d = camera.DistortionCoefficients();
    cv::undistortPoints(
        cv_pixels, expected, CameraMatrix(camera), d, cv::noArray(), cv::noArray(),
        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 500, 1e-14));
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const Eigen::Vector2d normalised = camera.Unproject(pixels[i]);
      // Compare in pixels: normalised error times the focal length.
      EXPECT_NEAR(normalised.x() * camera.fx, expected[i].x * camera.fx, 1e-6)
          << "pixel " << pixels[i].transpose();
      EXPECT_NEAR(normalised.y() * camera.fy, expected[i].y * camera.fy, 1e-6)
          << "pixel " << pixels[i].transpose();
    }
  }
}

TEST(CameraModelTest, EquidistantUnprojectMatchesOpenCvFisheyeUndistortPoints) {
  const CameraModel camera = TumViFisheye();
  // Inside the image circle: up to about 80 degrees off axis.
  const auto pixels = PixelGrid(camera, 250.0);
  ASSERT_GT(pixels.size(), 300u);
  std::vector<cv::Point2d> cv_pixels, expected;
  for (const auto& pixel : pixels) cv_pixels.emplace_back(pixel.x(), pixel.y());
  cv::fisheye::undistortPoints(
      cv_pixels, expected, CameraMatrix(camera), camera.DistortionCoefficients(), cv::noArray(),
      cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::MAX_ITER + cv::TermCriteria::EPS, 100, 1e-15));
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector2d normalised = camera.Unproject(pixels[i]);
    EXPECT_NEAR(normalised.x() * camera.fx, expected[i].x * camera.fx, 1e-6)
        << "pixel " << pixels[i].transpose();
    EXPECT_NEAR(normalised.y() * camera.fy, expected[i].y * camera.fy, 1e-6)
        << "pixel " << pixels[i].transpose();
  }
}

// Unproject then Distort returns the pixel, over the whole image (fisheye: inside the
// image circle), and Project(Unproject) agrees for points at any depth.
TEST(CameraModelTest, UnprojectInvertsProjectOverTheImage) {
  struct Case {
    CameraModel camera;
    double max_radius;
  };
  std::vector<Case> cases = {{TumViFisheye(), 255.0}};
  for (const CameraModel& camera : OpenCvFamily()) cases.push_back({camera, 1e9});
  for (const Case& c : cases) {
    double worst = 0.0;
    for (const auto& pixel : PixelGrid(c.camera, c.max_radius)) {
      const Eigen::Vector2d normalised = c.camera.Unproject(pixel);
      worst = std::max(worst, (c.camera.Distort(normalised) - pixel).norm());
      const auto reprojected = c.camera.Project(3.7 * normalised.homogeneous());
      ASSERT_TRUE(reprojected.has_value());
      worst = std::max(worst, (*reprojected - pixel).norm());
    }
    EXPECT_LT(worst, 1e-9) << DistortionModelName(c.camera.model);
  }
}

TEST(CameraModelTest, ProjectJacobianMatchesCentralDifferences) {
  std::vector<CameraModel> cameras = OpenCvFamily();
  cameras.push_back(TumViFisheye());
  for (const CameraModel& camera : cameras) {
    // Include a point on the optical axis (the fisheye's small-radius branch).
    auto points = RandomPointsInCone(0.9, 200, 11);
    points.emplace_back(0.0, 0.0, 2.0);
    points.emplace_back(1e-10, -2e-10, 1.5);
    for (const auto& p : points) {
      const Eigen::Matrix<double, 2, 3> analytic = camera.ProjectJacobian(p);
      Eigen::Matrix<double, 2, 3> numeric;
      const double h = 1e-6 * std::max(1.0, p.norm());
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(k);
        numeric.col(k) = (*camera.Project(p + step) - *camera.Project(p - step)) / (2.0 * h);
      }
      EXPECT_LT((analytic - numeric).norm(), 1e-6 * (1.0 + analytic.norm()))
          << DistortionModelName(camera.model) << " at " << p.transpose() << "\nanalytic\n"
          << analytic << "\nnumeric\n"
          << numeric;
    }
  }
}

TEST(CameraModelTest, CheckRejectsInvalidParameters) {
  EXPECT_TRUE(EurocRadTan().Check());
  EXPECT_TRUE(TumViFisheye().Check());
  EXPECT_FALSE(CameraModel().Check());
  CameraModel camera = EurocRadTan();
  camera.fx = -458.654;
  EXPECT_FALSE(camera.Check());
  camera = EurocRadTan();
  camera.height = 0;
  EXPECT_FALSE(camera.Check());
  std::string why;
  EXPECT_FALSE(camera.Check(&why));
  EXPECT_EQ(why, "height must be > 0, is 0");
  camera = EurocRadTan();
  camera.cy = std::nan("");
  EXPECT_FALSE(camera.Check());
  camera = EurocRadTan();
  camera.distortion[1] = INFINITY;
  EXPECT_FALSE(camera.Check());
  camera = EurocRadTan();
  camera.model = DistortionModel::kNone;  // coefficients left over
  EXPECT_FALSE(camera.Check());
  camera = TumViFisheye();
  camera.distortion[4] = 0.1;  // equidistant has four coefficients
  EXPECT_FALSE(camera.Check());
  for (const CameraModel& valid : OpenCvFamily()) EXPECT_TRUE(valid.Check());
  camera = EurocRadTan();
  camera.distortion[5] = 0.01;  // k4 belongs to the rational model
  EXPECT_FALSE(camera.Check());
  camera = LifeCamRational();
  camera.distortion[8] = 0.01;  // s1 belongs to the thin-prism model
  EXPECT_FALSE(camera.Check());
  camera = ThinPrism();
  camera.distortion[13] = 0.01;  // tauY belongs to the tilted model
  EXPECT_FALSE(camera.Check());
  camera = Tilted();
  camera.distortion[12] = 2.0;  // beyond 90 degrees
  EXPECT_FALSE(camera.Check());
}

TEST(CameraModelTest, DistortionCoefficientsAreTheModelsShareInOpenCvOrder) {
  EXPECT_TRUE(PinholeCamera(640, 480, 500.0).DistortionCoefficients().empty());
  EXPECT_EQ(EurocRadTan().DistortionCoefficients().size(), 5u);
  EXPECT_EQ(TumViFisheye().DistortionCoefficients().size(), 4u);
  EXPECT_EQ(LifeCamRational().DistortionCoefficients().size(), 8u);
  EXPECT_EQ(ThinPrism().DistortionCoefficients().size(), 12u);
  const std::vector<double> tilted = Tilted().DistortionCoefficients();
  ASSERT_EQ(tilted.size(), 14u);
  EXPECT_EQ(tilted[12], 0.03);
  EXPECT_EQ(tilted[13], -0.05);
}

TEST(CameraModelTest, InImageUsesPixelCentresAndBorder) {
  const CameraModel camera = EurocRadTan();
  EXPECT_TRUE(camera.InImage(Eigen::Vector2d(0.0, 0.0)));
  EXPECT_TRUE(camera.InImage(Eigen::Vector2d(751.0, 479.0)));
  EXPECT_FALSE(camera.InImage(Eigen::Vector2d(751.5, 10.0)));
  EXPECT_FALSE(camera.InImage(Eigen::Vector2d(5.0, 5.0), 10.0));
}

TEST(CameraModelTest, PinholeCameraCentresThePrincipalPoint) {
  const CameraModel camera = PinholeCamera(640, 480, 500.0);
  EXPECT_TRUE(camera.Check());
  EXPECT_EQ(camera.model, DistortionModel::kNone);
  EXPECT_DOUBLE_EQ(camera.fx, 500.0);
  EXPECT_DOUBLE_EQ(camera.fy, 500.0);
  EXPECT_DOUBLE_EQ(camera.cx, 319.5);
  EXPECT_DOUBLE_EQ(camera.cy, 239.5);
  // A point on the optical axis projects to the image centre.
  const auto pixel = camera.Project(Eigen::Vector3d(0.0, 0.0, 2.0));
  ASSERT_TRUE(pixel);
  EXPECT_DOUBLE_EQ(pixel->x(), 319.5);
  EXPECT_DOUBLE_EQ(pixel->y(), 239.5);
}

}  // namespace
}  // namespace arucoslam
