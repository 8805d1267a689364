#include "arucoslam/markers/sdf_export.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sdf/Box.hh>
#include <sdf/Geometry.hh>
#include <sdf/Link.hh>
#include <sdf/Material.hh>
#include <sdf/Model.hh>
#include <sdf/ParserConfig.hh>
#include <sdf/Pbr.hh>
#include <sdf/Root.hh>
#include <sdf/Visual.hh>
#include <sdf/World.hh>

#include "arucoslam/util/error.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

Rigid3 RigidFromEigenQuaternion(double w, double x, double y, double z, const Eigen::Vector3d& t) {
  return Rigid3(Eigen::Quaterniond(w, x, y, z).normalized(), t);
}

// Random poses plus the hard ones: identity, a marker facing down (pitch = +-90 degrees).
MarkerMap TestMap() {
  MarkerMap map;
  map.dictionary = "DICT_4X4_50";
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int id = 0; id < 8; ++id) {
    MarkerInfo marker;
    marker.id = id;
    marker.size = 0.1 + 0.05 * id;
    marker.world_from_marker =
        RigidFromEigenQuaternion(normal(rng), normal(rng), normal(rng), normal(rng),
                                 Eigen::Vector3d(5 * normal(rng), 5 * normal(rng), normal(rng)));
    map.markers[id] = marker;
  }
  map.markers[20] = MarkerInfo{20, 0.2, Rigid3(), true};
  const Eigen::Matrix3d pitch_up =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  map.markers[21] = MarkerInfo{21, 0.2, Rigid3(pitch_up, Eigen::Vector3d(1, 2, 3)), true};
  const Eigen::Matrix3d pitch_down_yawed = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                                            Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()))
                                               .toRotationMatrix();
  map.markers[22] =
      MarkerInfo{22, 0.2, Rigid3(pitch_down_yawed, Eigen::Vector3d(-1, 0, 0.5)), true};
  return map;
}

Eigen::Quaterniond ToEigen(const ignition::math::Quaterniond& q) {
  return Eigen::Quaterniond(q.W(), q.X(), q.Y(), q.Z());
}

TEST(SdfExportTest, RollPitchYawRebuildsTheRotation) {
  for (const auto& [id, marker] : TestMap().markers) {
    const Eigen::Vector3d rpy = RollPitchYaw(marker.world_from_marker.rotation);
    const Eigen::Matrix3d rebuilt = (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                                     Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                                     Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
                                        .toRotationMatrix();
    EXPECT_LT((rebuilt - marker.world_from_marker.RotationMatrix()).norm(), 1e-12) << id;
  }
}

TEST(SdfExportTest, BoxSideIncludesTheQuietZone) {
  MarkerImageOptions image;
  image.marker_size_px = 600;  // DICT_4X4_50: 6 cells of 100 px, quiet zone 2 cells = 200 px
  EXPECT_NEAR(MarkerBoxSide(0.3, "DICT_4X4_50", image), 0.3 * 1000.0 / 600.0, 1e-15);
  image.marker_size_px = 800;  // DICT_6X6_250: 8 cells of 100 px, quiet zone 200 px
  EXPECT_NEAR(MarkerBoxSide(0.2, "DICT_6X6_250", image), 0.2 * 1200.0 / 800.0, 1e-15);
  EXPECT_THROW(MarkerBoxSide(0.2, "DICT_9X9", image), InputError);
}

TEST(SdfExportTest, RejectsBadSizeAndOptions) {
  MarkerInfo marker{3, -0.1, Rigid3(), true};
  try {
    MarkerModelSdf(marker, {});
    FAIL() << "negative size accepted";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "marker 3");
    EXPECT_NE(error.message().find("size"), std::string::npos);
  }
  marker.size = 0.1;
  MarkerModelSdfOptions options;
  options.thickness = 0.0;
  EXPECT_THROW(MarkerModelSdf(marker, options), InputError);
}

// Writes the folder, parses it back with libsdformat and compares every model with the map.
TEST(SdfExportTest, ParsedBackWorldMatchesTheMap) {
  const ScratchFolder scratch("sdf_export_test");
  const fs::path& folder = scratch.path();
  const MarkerMap map = TestMap();
  MarkerImageOptions image;
  image.marker_size_px = 120;
  const fs::path world_path = WriteMarkerSdfFolder(map, folder, image);

  sdf::ParserConfig config;
  config.AddURIPath("model://", folder.string());  // what GZ_SIM_RESOURCE_PATH=folder does
  sdf::Root root;
  const sdf::Errors errors = root.Load(world_path.string(), config);
  for (const sdf::Error& error : errors) ADD_FAILURE() << error.Message();
  ASSERT_EQ(root.WorldCount(), 1u);
  const sdf::World* world = root.WorldByIndex(0);
  ASSERT_EQ(world->ModelCount(), map.markers.size());
  for (const auto& [id, marker] : map.markers) {
    const sdf::Model* model = world->ModelByName(MarkerModelName(id));
    ASSERT_NE(model, nullptr) << id;
    EXPECT_TRUE(model->Static());
    const ignition::math::Pose3d pose = model->RawPose();
    const Eigen::Vector3d position(pose.Pos().X(), pose.Pos().Y(), pose.Pos().Z());
    EXPECT_LT((position - marker.world_from_marker.translation).norm(), 1e-9) << id;
    EXPECT_LT(RotationAngle(ToEigen(pose.Rot()).inverse() * marker.world_from_marker.rotation),
              1e-9)
        << id;

    ASSERT_EQ(model->LinkCount(), 1u);
    const sdf::Link* link = model->LinkByIndex(0);
    ASSERT_EQ(link->VisualCount(), 1u);
    EXPECT_EQ(link->CollisionCount(), 1u);
    const sdf::Visual* visual = link->VisualByIndex(0);
    // The printed face (box +z) lies in the marker plane.
    EXPECT_NEAR(visual->RawPose().Pos().Z() + 0.5 * 0.002, 0.0, 1e-15);
    const sdf::Box* box = visual->Geom()->BoxShape();
    ASSERT_NE(box, nullptr);
    const double side = marker.size * 200.0 / 120.0;  // 6 cells of 20 px + 2 x 40 px
    EXPECT_NEAR(box->Size().X(), side, 1e-12);
    EXPECT_NEAR(box->Size().Y(), side, 1e-12);
    EXPECT_NEAR(box->Size().Z(), 0.002, 1e-15);
    const sdf::PbrWorkflow* metal =
        visual->Material()->PbrMaterial()->Workflow(sdf::PbrWorkflowType::METAL);
    ASSERT_NE(metal, nullptr);
    const fs::path texture =
        fs::path(visual->Material()->FilePath()).parent_path() / metal->AlbedoMap();
    const cv::Mat png = cv::imread(texture.string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(png.empty()) << texture;
    EXPECT_EQ(png.cols, 200);
    EXPECT_EQ(png.at<uchar>(0, 0), 255);  // white quiet zone
    EXPECT_EQ(png.at<uchar>(45, 45), 0);  // black border of the marker
  }
}

}  // namespace
}  // namespace arucoslam
