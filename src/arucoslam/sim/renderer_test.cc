#include "arucoslam/sim/renderer.h"

#include <gtest/gtest.h>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "arucoslam/markers/dictionary.h"
#include "arucoslam/markers/marker_image.h"
#include "arucoslam/sim/world_model.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

// Camera looking from `position` at `target`, world z up (camera y down).
Rigid3 LookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - position).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d rotation;
  rotation << x, y, z;
  return Rigid3(rotation, position);
}

CameraModel TestCamera() {
  CameraModel camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = 460.0;
  camera.fy = 455.0;
  camera.cx = 318.3;
  camera.cy = 241.7;
  return camera;
}

std::string PoseText(const Rigid3& pose) {
  const Eigen::Vector3d rpy = pose.RotationMatrix().eulerAngles(2, 1, 0);  // yaw pitch roll
  std::ostringstream text;
  text.precision(17);
  text << pose.translation.x() << ' ' << pose.translation.y() << ' ' << pose.translation.z()
       << ' ' << rpy[2] << ' ' << rpy[1] << ' ' << rpy[0];
  return text.str();
}

class RendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("arucoslam_renderer_test_" + std::to_string(getpid()));
    fs::create_directories(dir_);
  }
  // ARUCOSLAM_KEEP_TEST_OUTPUT=1 keeps the rendered images for a look.
  void TearDown() override {
    if (std::getenv("ARUCOSLAM_KEEP_TEST_OUTPUT") == nullptr) fs::remove_all(dir_);
  }

  WorldModel LoadWorld(const std::string& models) {
    const fs::path path = dir_ / "world.sdf";
    std::ofstream(path) << "<?xml version=\"1.0\"?><sdf version=\"1.9\"><world name=\"w\">"
                        << models << "</world></sdf>";
    return LoadWorldModel(path);
  }

  static std::string Visual(const std::string& name, const std::string& pose,
                            const std::string& geometry, const std::string& material) {
    return "<model name=\"" + name + "\"><static>true</static><pose>" + pose +
           "</pose><link name=\"l\"><visual name=\"v\"><geometry>" + geometry +
           "</geometry><material>" + material + "</material></visual></link></model>";
  }

  fs::path dir_;
};

// Dots at asymmetric texture positions (u, v): a mirrored or rotated mapping moves them.
const std::vector<Eigen::Vector2d> kDotUvs = {{0.2, 0.3}, {0.7, 0.25}, {0.35, 0.8}};

// Intensity-weighted centroids of the dark blobs of `grey` (one per connected component).
std::vector<Eigen::Vector2d> DarkBlobCentroids(const cv::Mat& grey) {
  cv::Mat mask;
  cv::threshold(grey, mask, 50, 255, cv::THRESH_BINARY_INV);  // dots are black
  cv::dilate(mask, mask, cv::Mat(), cv::Point(-1, -1), 2);
  cv::Mat labels;
  const int count = cv::connectedComponents(mask, labels);
  std::vector<Eigen::Vector3d> sums(count, Eigen::Vector3d::Zero());
  for (int v = 0; v < grey.rows; ++v) {
    for (int u = 0; u < grey.cols; ++u) {
      const int label = labels.at<int>(v, u);
      if (label == 0) continue;
      // Darkness below the plane's level (about 150), so the plane itself weighs nothing.
      const double weight = std::max(0.0, 120.0 - grey.at<uchar>(v, u));
      sums[label] += Eigen::Vector3d(weight * u, weight * v, weight);
    }
  }
  std::vector<Eigen::Vector2d> centroids;
  for (int label = 1; label < count; ++label) {
    centroids.emplace_back(sums[label].x() / sums[label].z(), sums[label].y() / sums[label].z());
  }
  return centroids;
}

// Projects the dots of a textured plane and compares them with the rendered blobs.
void ExpectDotsWhereProjected(const WorldModel& world, const CameraModel& camera,
                              const Rigid3& world_from_cam, const std::string& save_as) {
  RenderOptions options;
  Renderer renderer(world, camera, options);
  const RenderedFrame frame = renderer.Render(world_from_cam);
  if (!save_as.empty()) cv::imwrite(save_as, frame.grey);
  const std::vector<Eigen::Vector2d> blobs = DarkBlobCentroids(frame.grey);
  ASSERT_EQ(blobs.size(), kDotUvs.size());
  const WorldPrimitive& plane = world.primitives.at(0);
  for (const Eigen::Vector2d& uv : kDotUvs) {
    const Eigen::Vector3d p_in_shape((uv.x() - 0.5) * plane.size.x(),
                                     (0.5 - uv.y()) * plane.size.y(), 0.0);
    const Eigen::Vector3d p_in_cam =
        world_from_cam.Inverse() * (plane.world_from_shape * p_in_shape);
    const auto pixel = camera.Project(p_in_cam);
    ASSERT_TRUE(pixel.has_value());
    double best = 1e9;
    for (const Eigen::Vector2d& blob : blobs) best = std::min(best, (blob - *pixel).norm());
    std::printf("dot at uv (%.2f, %.2f): %.3f px from its projection\n", uv.x(), uv.y(), best);
    EXPECT_LT(best, 0.5) << "dot at uv " << uv.transpose() << " projected to "
                         << pixel->transpose();
  }
}

class DotPlaneTest : public RendererTest {
 protected:
  WorldModel DotWorld() {
    cv::Mat texture(800, 800, CV_8UC3, cv::Scalar::all(255));
    for (const Eigen::Vector2d& uv : kDotUvs) {
      // Texture coordinate u is at pixel u * 800 - 0.5 (pixel centres at integers).
      cv::circle(texture,
                 cv::Point(std::lround((uv.x() * 800 - 0.5) * 16),
                           std::lround((uv.y() * 800 - 0.5) * 16)),
                 10 * 16,
                 cv::Scalar::all(0), cv::FILLED, cv::LINE_AA, 4);
    }
    cv::imwrite((dir_ / "dots.png").string(), texture);
    // A 2 m x 2 m plane standing 3 m ahead, turned 30 degrees about world z and tilted.
    return LoadWorld(Visual("dots", "3 0.2 1.0 1.2 0.1 2.0",
                            "<plane><normal>0 0 1</normal><size>2 2</size></plane>",
                            "<pbr><metal><albedo_map>dots.png</albedo_map></metal></pbr>"));
  }
};

TEST_F(DotPlaneTest, TexturedPointLandsWhereCameraProjects) {
  const WorldModel world = DotWorld();
  const Rigid3 world_from_cam = LookAt({0.1, -0.3, 1.1}, {3.0, 0.25, 0.95});
  ExpectDotsWhereProjected(world, TestCamera(), world_from_cam,
                           (dir_ / "dots_pinhole.png").string());
}

TEST_F(DotPlaneTest, TexturedPointLandsWhereDistortedCameraProjects) {
  const WorldModel world = DotWorld();
  CameraModel camera = TestCamera();
  camera.model = DistortionModel::kRadTan;
  camera.distortion = {-0.28, 0.07, 0.0002, 0.00002, 0.0};  // EuRoC-like barrel distortion
  const Rigid3 world_from_cam = LookAt({0.4, 0.6, 1.3}, {3.0, 0.1, 0.9});
  ExpectDotsWhereProjected(world, camera, world_from_cam, "");
}

TEST_F(RendererTest, MarkerPoseRecoveredWithinOnePercent) {
  const std::string dictionary = "DICT_4X4_50";
  MarkerImageOptions marker_options;
  marker_options.marker_size_px = 480;
  const cv::Mat marker = DrawMarkerImage(dictionary, 7, marker_options);
  cv::imwrite((dir_ / "marker_7.png").string(), marker);
  const double box_side = 0.45;  // quiet zone included
  const double black_side = box_side * marker_options.marker_size_px / marker.cols;
  // Marker on a wall at camera height, facing -x (printed face +z of the box).
  // Marker x along world -y, y up (world z), printed face z towards world -x; its face lies
  // on the wall's surface x = 4.
  Eigen::Matrix3d marker_axes;
  marker_axes << 0, 0, -1,  //
      -1, 0, 0,             //
      0, 1, 0;
  const Rigid3 world_from_marker(marker_axes, Eigen::Vector3d(3.998, 1.5, 0.8));
  const Rigid3 world_from_box = world_from_marker * Rigid3(Eigen::Quaterniond::Identity(),
                                                          Eigen::Vector3d(0, 0, -0.001));
  const WorldModel world = LoadWorld(
      Visual("wall", "4.2 1.5 1.5 0 0 0", "<box><size>0.4 6 3</size></box>",
             "<diffuse>0.45 0.45 0.45 1</diffuse>") +
      Visual("marker_7", PoseText(world_from_box),
             "<box><size>" + std::to_string(box_side) + " " + std::to_string(box_side) +
                 " 0.002</size></box>",
             "<pbr><metal><albedo_map>marker_7.png</albedo_map></metal></pbr>"));
  const CameraModel camera = TestCamera();
  Renderer renderer(world, camera, RenderOptions{});
  const cv::Mat k = (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy,
                     camera.cy, 0, 0, 1);
  const float half = static_cast<float>(black_side / 2);
  const std::vector<cv::Point3f> object = {
      {-half, half, 0}, {half, half, 0}, {half, -half, 0}, {-half, -half, 0}};
  int index = 0;
  for (const Eigen::Vector3d& position :
        {Eigen::Vector3d(2.6, 1.4, 0.7), Eigen::Vector3d(2.5, 0.9, 0.9),
        Eigen::Vector3d(2.7, 2.2, 0.6)}) {
    const Rigid3 world_from_cam = LookAt(position, world_from_marker.translation);
    const RenderedFrame frame = renderer.Render(world_from_cam);
    cv::imwrite((dir_ / ("marker_view_" + std::to_string(index++) + ".png")).string(), frame.grey);
    std::vector<int> ids;
    std::vector<std::vector<cv::Point2f>> corners;
    auto parameters = cv::aruco::DetectorParameters::create();
    parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
    cv::aruco::detectMarkers(frame.grey, DictionaryFromName(dictionary), corners, ids,
                             parameters);
    ASSERT_EQ(ids.size(), 1u) << "at " << position.transpose();
    EXPECT_EQ(ids[0], 7);
    cv::Mat rvec, tvec;
    ASSERT_TRUE(cv::solvePnP(object, corners[0], k, cv::Mat(), rvec, tvec, false,
                             cv::SOLVEPNP_IPPE_SQUARE));
    cv::Mat rotation_cv;
    cv::Rodrigues(rvec, rotation_cv);
    Eigen::Matrix3d rotation;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) rotation(r, c) = rotation_cv.at<double>(r, c);
    const Rigid3 cam_from_marker(
        rotation, Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)));
    const Rigid3 estimated = world_from_marker * cam_from_marker.Inverse();
    const double distance = (position - world_from_marker.translation).norm();
    std::printf("marker at %.2f m: camera position error %.4f m (%.2f%%)\n", distance,
                (estimated.translation - position).norm(),
                100.0 * (estimated.translation - position).norm() / distance);
    EXPECT_LT((estimated.translation - position).norm(), 0.01 * distance)
        << "camera at " << position.transpose() << " estimated at "
        << estimated.translation.transpose();
    // Corners where the camera model puts them.
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d corner(object[c].x, object[c].y, object[c].z);
      const auto pixel =
          camera.Project(world_from_cam.Inverse() * (world_from_marker * corner));
      ASSERT_TRUE(pixel.has_value());
      EXPECT_LT((Eigen::Vector2d(corners[0][c].x, corners[0][c].y) - *pixel).norm(), 0.5)
          << "corner " << c << " detected at " << corners[0][c] << ", projects to "
          << pixel->transpose();
    }
  }
}

TEST_F(RendererTest, DepthEqualsDistanceAlongAxisForAPlane) {
  // A wall x = 5 seen obliquely: z of the ray through pixel (u, v) hitting it.
  const WorldModel world = LoadWorld(Visual(
      "wall", "5 0 0 0 0 0", "<plane><normal>-1 0 0</normal><size>40 40</size></plane>",
      "<diffuse>0.6 0.6 0.6 1</diffuse>"));
  const CameraModel camera = TestCamera();
  RenderOptions options;
  options.depth = true;
  Renderer renderer(world, camera, options);
  const Rigid3 world_from_cam = LookAt({0.5, 0.3, 1.0}, {5.0, 2.0, 1.5});
  const RenderedFrame frame = renderer.Render(world_from_cam);
  ASSERT_EQ(frame.depth.type(), CV_32FC1);
  double max_error = 0.0;
  for (int v = 0; v < camera.height; v += 7) {
    for (int u = 0; u < camera.width; u += 7) {
      const Eigen::Vector2d n = camera.Unproject(Eigen::Vector2d(u, v));
      const Eigen::Vector3d ray_in_world = world_from_cam.rotation * Eigen::Vector3d(n.x(), n.y(), 1);
      const double z = (5.0 - world_from_cam.translation.x()) / ray_in_world.x();
      max_error = std::max(max_error, std::abs(frame.depth.at<float>(v, u) - z));
    }
  }
  std::printf("depth: max error %.2e m\n", max_error);
  EXPECT_LT(max_error, 1e-3);  // metres, over depths of about 4.5 to 9 m
}

TEST_F(RendererTest, FrustumCullingDoesNotChangeTheImage) {
  // Boxes and cylinders all around the camera, some straddling the edges of the view.
  std::string models;
  for (int i = 0; i < 24; ++i) {
    const double angle = i * 2.0 * M_PI / 24.0;
    const double distance = 1.0 + 0.4 * (i % 5);
    const std::string pose = std::to_string(distance * std::cos(angle)) + " " +
                             std::to_string(distance * std::sin(angle)) + " " +
                             std::to_string(0.2 * (i % 3)) + " 0 0 " + std::to_string(angle);
    const std::string geometry = i % 2 == 0 ? "<box><size>0.5 0.3 0.8</size></box>"
                                            : "<cylinder><radius>0.2</radius><length>1.5</length></cylinder>";
    const double grey = 0.2 + 0.03 * i;
    models += Visual("m" + std::to_string(i), pose, geometry,
                     "<diffuse>" + std::to_string(grey) + " 0.5 0.5 1</diffuse>");
  }
  const WorldModel world = LoadWorld(models);
  RenderOptions culled;
  RenderOptions unculled;
  unculled.frustum_culling = false;
  Renderer a(world, TestCamera(), culled);
  Renderer b(world, TestCamera(), unculled);
  for (double yaw = 0.0; yaw < 2.0 * M_PI; yaw += 0.7) {
    const Rigid3 pose = LookAt({0, 0, 0.3}, {std::cos(yaw), std::sin(yaw), 0.25});
    const cv::Mat image_a = a.Render(pose).grey;
    EXPECT_EQ(cv::norm(image_a, b.Render(pose).grey, cv::NORM_INF), 0.0) << "yaw " << yaw;
    EXPECT_GT(cv::norm(image_a, cv::Mat(image_a.size(), CV_8UC1, cv::Scalar(179)),
                       cv::NORM_L1) / image_a.total(), 5.0);  // not just background
  }
}

TEST_F(RendererTest, NoiseIsSeededAndBlurAverages) {
  const WorldModel world = LoadWorld(Visual(
      "wall", "5 0 0 0 0 0", "<box><size>0.2 1 1</size></box>", "<diffuse>0.1 0.1 0.1 1</diffuse>"));
  RenderOptions options;
  options.noise_sigma = 3.0;
  Renderer renderer(world, TestCamera(), options);
  const Rigid3 pose = LookAt({0, 0, 0.2}, {5, 0, 0.2});
  const cv::Mat a = renderer.Render(pose, 12).grey;
  const cv::Mat b = renderer.Render(pose, 12).grey;
  const cv::Mat c = renderer.Render(pose, 13).grey;
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1) / a.total(), 1.0);  // about 3.4 grey levels apart
  cv::Mat difference;
  cv::absdiff(a, c, difference);
  // Blur: two poses a box width apart give a half-dark smear.
  options.noise_sigma = 0.0;
  Renderer sharp(world, TestCamera(), options);
  const Rigid3 moved = LookAt({0, 0.5, 0.2}, {5, 0.5, 0.2});
  const cv::Mat single = sharp.Render(pose).grey;
  const cv::Mat blurred = sharp.Render(std::vector<Rigid3>{pose, moved}).grey;
  const cv::Mat other = sharp.Render(moved).grey;
  cv::Mat mean;
  cv::addWeighted(single, 0.5, other, 0.5, 0.0, mean);
  EXPECT_LE(cv::norm(blurred, mean, cv::NORM_INF), 1.0);
  EXPECT_GT(cv::norm(blurred, single, cv::NORM_INF), 30.0);
}

}  // namespace
}  // namespace arucoslam
