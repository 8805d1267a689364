#include "arucoslam/sim/factory_world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <sdf/sdf.hh>
#include <set>
#include <sstream>

#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/sim/path.h"
#include "arucoslam/sim/world_model.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

class FactoryWorldTest : public ::testing::Test {
 protected:
  fs::path Write(const FactoryOptions& options, const std::string& name) {
    const fs::path dir = root_ / name;
    fs::create_directories(dir);
    WriteFactoryWorld(BuildFactoryWorld(options), dir);
    return dir;
  }

  ScratchFolder scratch_{"factory_test"};
  const fs::path& root_ = scratch_.path();
};

std::string FileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

std::map<std::string, std::string> FolderBytes(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file())
      files[fs::relative(entry.path(), dir).string()] = FileBytes(entry.path());
  }
  return files;
}

TEST_F(FactoryWorldTest, SameSeedGivesIdenticalFiles) {
  FactoryOptions options;
  options.seed = 5;
  options.aisles = 2;
  options.aisle_length_m = 10.0;
  const auto a = FolderBytes(Write(options, "a"));
  const auto b = FolderBytes(Write(options, "b"));
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, bytes] : a) {
    ASSERT_TRUE(b.count(name)) << name;
    EXPECT_TRUE(bytes == b.at(name)) << name << " differs";
  }
  EXPECT_TRUE(a.count("world.sdf") && a.count("markers.json") && a.count("path.json"));
  EXPECT_TRUE(a.count("textures/floor_0.png") && a.count("markers/0.png"));
  options.seed = 6;
  const auto c = FolderBytes(Write(options, "c"));
  EXPECT_NE(a.at("textures/floor_0.png"), c.at("textures/floor_0.png"));
  EXPECT_NE(a.at("world.sdf"), c.at("world.sdf"));
}

TEST_F(FactoryWorldTest, DefaultRouteIsAShortLoopWithATightTurn) {
  const FactoryWorld world = BuildFactoryWorld(FactoryOptions());
  const std::vector<RouteSample> route = PlanRoute(world.default_route);
  // The demo sequence: at most 3 minutes of driving, aimed at 60-90 s.
  EXPECT_LE(RouteDuration(route), 90.0);
  EXPECT_GE(RouteDuration(route), 45.0);
  const std::vector<TimedPose> poses = GenerateCameraPath(world.default_route, PathRun::kRepeat);
  EXPECT_LT(
      (poses.back().world_from_cam.translation - poses.front().world_from_cam.translation).norm(),
      0.5);
  double max_speed = 0.0, best_turn = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Vector3d p = poses[i].world_from_cam.translation;
    EXPECT_GE(p.z(), 0.3);
    EXPECT_LE(p.z(), 1.0);
    if (i > 0) {
      max_speed = std::max(max_speed, (p - poses[i - 1].world_from_cam.translation).norm() * 30.0);
    }
    double travelled = 0.0, turned = 0.0;
    for (std::size_t j = i + 1; j < poses.size() && travelled < 5.0; ++j) {
      auto heading = [&poses](std::size_t k) {
        const Eigen::Vector3d f = poses[k].world_from_cam.rotation * Eigen::Vector3d::UnitZ();
        return std::atan2(f.y(), f.x());
      };
      travelled +=
          (poses[j].world_from_cam.translation - poses[j - 1].world_from_cam.translation).norm();
      turned += std::remainder(heading(j) - heading(j - 1), 2 * kPi);
      best_turn = std::max(best_turn, std::abs(turned));
    }
  }
  EXPECT_LE(max_speed, 1.02);
  EXPECT_GE(best_turn * 180.0 / kPi, 150.0);
}

// Metres driven along `poses` while `target` is within `max_angle_deg` of the camera's axis
// and nearer than `max_distance_m` (and, with `normal`, the camera within `max_angle_deg` of
// that direction out of the target).
double DistanceDrivenFacing(const std::vector<TimedPose>& poses, const Eigen::Vector3d& target,
                            double max_angle_deg, double max_distance_m,
                            const Eigen::Vector3d* normal = nullptr) {
  const double min_cos = std::cos(max_angle_deg * kPi / 180);
  double distance = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const Rigid3& cam = poses[i].world_from_cam;
    const Eigen::Vector3d to_target = target - cam.translation;
    const Eigen::Vector3d forward = cam.rotation * Eigen::Vector3d::UnitZ();
    if (forward.dot(to_target.normalized()) > min_cos &&
        (normal == nullptr || normal->dot(-to_target.normalized()) > min_cos) &&
        to_target.norm() < max_distance_m) {
      distance += (cam.translation - poses[i - 1].world_from_cam.translation).norm();
    }
  }
  return distance;
}

// Every dock the route visits is approached head-on: for at least 2 m of driving the marker
// is ahead of the camera, within 25 degrees of its axis, with its +z facing the camera.
TEST_F(FactoryWorldTest, DockMarkersFaceTheApproach) {
  FactoryOptions options;
  options.wall_marker_spacing_m = 0.0;  // the docks only
  options.markers_per_dock = 2;
  const FactoryWorld world = BuildFactoryWorld(options);
  const std::vector<TimedPose> poses = GenerateCameraPath(world.default_route, PathRun::kTeach);
  int visited = 0;
  for (const FactoryDock& dock : world.docks) {
    ASSERT_EQ(dock.marker_ids.size(), 2u);
    for (const int id : dock.marker_ids) {
      const MarkerInfo& marker = world.markers.markers.at(id);
      const Eigen::Vector3d z = marker.world_from_marker.rotation * Eigen::Vector3d::UnitZ();
      const Eigen::Vector3d y = marker.world_from_marker.rotation * Eigen::Vector3d::UnitY();
      EXPECT_NEAR(z.head<2>().dot(dock.facing), 1.0, 1e-12);  // out of the board
      EXPECT_NEAR(y.z(), 1.0, 1e-12);                         // upright
      EXPECT_NEAR(marker.world_from_marker.translation.z(), options.camera_height_m, 1e-12);
      const double facing_distance =
          DistanceDrivenFacing(poses, marker.world_from_marker.translation, 25.0, 8.0, &z);
      EXPECT_EQ(facing_distance >= 2.0, dock.on_default_route)
          << dock.name << " " << facing_distance;
    }
    visited += dock.on_default_route;
  }
  EXPECT_EQ(visited, 2);
  EXPECT_EQ(world.docks.size(), 2u * (options.aisles + 1));
}

// The robot (0.3 m either side of the camera) never drives into anything that stands on
// the floor below camera height.
TEST_F(FactoryWorldTest, RouteKeepsClearOfSolids) {
  const FactoryWorld world = BuildFactoryWorld(FactoryOptions());
  const std::vector<RouteSample> route = PlanRoute(world.default_route);
  for (const FactoryModel& model : world.models) {
    for (const FactoryVisual& visual : model.visuals) {
      const Rigid3 world_from_visual = model.world_from_model * visual.model_from_visual;
      const Eigen::Vector3d half = visual.size / 2;
      const double bottom = world_from_visual.translation.z() - half.z();
      if (bottom > 1.0 || world_from_visual.translation.z() + half.z() < 0.05) continue;
      for (std::size_t i = 0; i < route.size(); i += 10) {
        const Eigen::Vector3d p =
            world_from_visual.Inverse() *
            Eigen::Vector3d(route[i].x, route[i].y, world_from_visual.translation.z());
        const bool inside = std::abs(p.x()) < half.x() + 0.3 && std::abs(p.y()) < half.y() + 0.3;
        ASSERT_FALSE(inside) << model.name << "::" << visual.name << " at route distance "
                             << route[i].distance_m;
      }
    }
  }
}

Eigen::Quaterniond ToEigen(const ignition::math::Quaterniond& q) {
  return Eigen::Quaterniond(q.W(), q.X(), q.Y(), q.Z());
}

// The corridor-end boards hang on the corridor's y = 0 wall facing +y, ids after the docks'
// (the dock markers unchanged), and the default route faces the east one in its turn: within
// 35 degrees of the camera axis and 4 m for at least 0.3 m of driving.
TEST_F(FactoryWorldTest, CorridorEndMarkersFaceTheRouteInItsTurn) {
  FactoryOptions options;
  options.wall_marker_spacing_m = 0.0;  // the docks only
  const FactoryWorld plain = BuildFactoryWorld(options);
  options.corridor_end_markers = true;
  const FactoryWorld world = BuildFactoryWorld(options);
  ASSERT_EQ(world.markers.markers.size(), plain.markers.markers.size() + 2);
  for (const auto& [id, marker] : plain.markers.markers) {
    EXPECT_LT((world.markers.markers.at(id).world_from_marker.translation -
               marker.world_from_marker.translation)
                  .norm(),
              1e-12);
  }
  const int first = static_cast<int>(plain.markers.markers.size());
  const std::vector<TimedPose> poses = GenerateCameraPath(world.default_route, PathRun::kTeach);
  for (const int id : {first, first + 1}) {
    const MarkerInfo& marker = world.markers.markers.at(id);
    const Eigen::Vector3d z = marker.world_from_marker.rotation * Eigen::Vector3d::UnitZ();
    EXPECT_NEAR(z.y(), 1.0, 1e-12);
    EXPECT_NEAR(marker.world_from_marker.translation.y(), 0.022, 1e-12);  // on a 2 cm board
    EXPECT_NEAR(marker.world_from_marker.translation.z(), options.camera_height_m, 1e-12);
  }
  const MarkerInfo& east = world.markers.markers.at(first + 1);
  EXPECT_GT(east.world_from_marker.translation.x(), world.hall_length_m / 2);
  EXPECT_GE(DistanceDrivenFacing(poses, east.world_from_marker.translation, 35.0, 4.0), 0.3);
}

// Wall boards every 3 m along the corridor's y = 0 wall: facing +y at camera height, at
// least 3 m apart, clear of the pillars, ids after the docks' (dock markers unchanged); the
// corridor-end flag adds no second board at the ends; too many boards for the dictionary
// and a spacing out of range are refused.
TEST_F(FactoryWorldTest, WallMarkersLineTheCorridorClearOfThePillars) {
  FactoryOptions options;
  options.wall_marker_spacing_m = 0.0;  // the docks only
  const FactoryWorld plain = BuildFactoryWorld(options);
  options.wall_marker_spacing_m = 3.0;
  const FactoryWorld world = BuildFactoryWorld(options);
  const int docks = static_cast<int>(plain.markers.markers.size());
  const int boards = static_cast<int>(world.markers.markers.size()) - docks;
  const double length = world.hall_length_m;
  // (length - 3.6) / 3 + 1 positions, minus those on a pillar.
  EXPECT_GE(boards, static_cast<int>((length - 3.6) / 3.0) - 2);
  EXPECT_LE(boards, static_cast<int>((length - 3.6) / 3.0) + 1);
  const int pillars = std::max(2, static_cast<int>(std::round(length / 8.0)));
  double previous_x = -1e9;
  for (int id = docks; id < docks + boards; ++id) {
    const MarkerInfo& marker = world.markers.markers.at(id);
    const Eigen::Vector3d& centre = marker.world_from_marker.translation;
    EXPECT_NEAR((marker.world_from_marker.rotation * Eigen::Vector3d::UnitZ()).y(), 1.0, 1e-12);
    EXPECT_NEAR(centre.y(), 0.022, 1e-12);
    EXPECT_NEAR(centre.z(), options.camera_height_m, 1e-12);
    EXPECT_GE(centre.x(), 1.8 - 1e-9);
    EXPECT_LE(centre.x(), length - 1.8 + 1e-9);
    EXPECT_GE(centre.x() - previous_x, 3.0 - 1e-9);
    previous_x = centre.x();
    for (int i = 1; i < pillars; ++i) EXPECT_GT(std::abs(centre.x() - length * i / pillars), 0.5);
  }
  for (const auto& [id, marker] : plain.markers.markers) {
    EXPECT_LT((world.markers.markers.at(id).world_from_marker.translation -
               marker.world_from_marker.translation)
                  .norm(),
              1e-12);
  }
  // With the corridor-end boards too: one board at each end, none doubled.
  options.corridor_end_markers = true;
  const FactoryWorld both = BuildFactoryWorld(options);
  std::vector<double> xs;
  for (int id = docks; id < static_cast<int>(both.markers.markers.size()); ++id) {
    xs.push_back(both.markers.markers.at(id).world_from_marker.translation.x());
  }
  ASSERT_GE(xs.size(), static_cast<std::size_t>(boards));
  EXPECT_NEAR(xs.front(), 1.8, 1e-9);
  EXPECT_NEAR(xs.back(), length - 1.8, 1e-9);
  for (std::size_t i = 1; i < xs.size(); ++i) EXPECT_GT(xs[i] - xs[i - 1], 0.5);
  options.wall_marker_spacing_m = 1.0;
  options.markers_per_dock = 3;  // 24 dock markers and 3 per board: more than 50 ids
  EXPECT_THROW(BuildFactoryWorld(options), InputError);
  options.markers_per_dock = 1;
  options.wall_marker_spacing_m = 0.5;
  EXPECT_THROW(BuildFactoryWorld(options), InputError);
}

TEST_F(FactoryWorldTest, SdformatParsesTheWorldAndMarkerPosesMatchTheJson) {
  FactoryOptions options;
  options.aisles = 2;
  options.aisle_length_m = 12.0;
  options.markers_per_dock = 2;
  options.wall_marker_spacing_m = 0.0;  // the docks only
  options.texture = TextureLevel::kHigh;
  const fs::path dir = Write(options, "sdf");
  sdf::Root root;
  const sdf::Errors errors = root.Load((dir / "world.sdf").string());
  for (const sdf::Error& error : errors) ADD_FAILURE() << error.Message();
  ASSERT_EQ(root.WorldCount(), 1u);
  const sdf::World* sdf_world = root.WorldByIndex(0);
  const MarkerMap markers = ReadMarkerMapJson(dir / "markers.json");
  EXPECT_EQ(markers.markers.size(), 12u);  // 2 lanes + corridor, 2 ends, 2 per dock
  for (const auto& [id, marker] : markers.markers) {
    const sdf::Model* model = sdf_world->ModelByName("marker_" + std::to_string(id));
    ASSERT_NE(model, nullptr) << id;
    EXPECT_TRUE(model->Static());
    const ignition::math::Pose3d pose = model->RawPose();
    const Eigen::Vector3d position(pose.Pos().X(), pose.Pos().Y(), pose.Pos().Z());
    EXPECT_LT((position - marker.world_from_marker.translation).norm(), 1e-9) << id;
    EXPECT_LT(RotationAngle(ToEigen(pose.Rot()).inverse() * marker.world_from_marker.rotation),
              1e-9)
        << id;
    EXPECT_FALSE(cv::imread((dir / "markers" / (std::to_string(id) + ".png")).string()).empty());
  }
  // Every texture named exists, and textures stay small (the renderer loads them all).
  std::set<std::string> textures;
  for (uint64_t m = 0; m < sdf_world->ModelCount(); ++m) {
    const sdf::Link* link = sdf_world->ModelByIndex(m)->LinkByIndex(0);
    for (uint64_t v = 0; v < link->VisualCount(); ++v) {
      const sdf::Material* material = link->VisualByIndex(v)->Material();
      ASSERT_NE(material, nullptr);
      if (material->PbrMaterial() == nullptr) continue;
      textures.insert(material->PbrMaterial()->Workflow(sdf::PbrWorkflowType::METAL)->AlbedoMap());
    }
  }
  EXPECT_GT(textures.size(), 20u);
  for (const std::string& texture : textures) {
    const cv::Mat image = cv::imread((dir / texture).string());
    ASSERT_FALSE(image.empty()) << texture;
    if (texture.rfind("textures/floor", 0) != 0) {
      EXPECT_LE(std::max(image.cols, image.rows), 1024) << texture;
    }
  }
  // The renderer's loader reads the same world: one primitive per visual.
  const FactoryWorld world = BuildFactoryWorld(options);
  std::size_t visuals = world.markers.markers.size();
  for (const FactoryModel& model : world.models) visuals += model.visuals.size();
  EXPECT_EQ(LoadWorldModel(dir / "world.sdf").primitives.size(), visuals);
}

TEST_F(FactoryWorldTest, MarkersOffAndBadOptions) {
  FactoryOptions options;
  options.wall_marker_spacing_m = 0.0;  // the docks only
  options.markers = false;
  const FactoryWorld world = BuildFactoryWorld(options);
  EXPECT_TRUE(world.markers.markers.empty());
  EXPECT_EQ(world.docks.size(), 8u);
  options.markers = true;
  options.aisles = 8;
  options.markers_per_dock = 3;  // 18 docks x 3 > 50 ids of DICT_4X4_50
  EXPECT_THROW(BuildFactoryWorld(options), InputError);
  options.dictionary = "DICT_6X6_250";
  EXPECT_EQ(BuildFactoryWorld(options).markers.markers.size(), 54u);
  options.dictionary = "DICT_NOPE";
  EXPECT_THROW(BuildFactoryWorld(options), InputError);
  EXPECT_THROW(TextureLevelFromName("shiny"), InputError);
  EXPECT_EQ(TextureLevelFromName("high"), TextureLevel::kHigh);
  FactoryOptions bad;
  bad.aisles = 0;
  EXPECT_THROW(BuildFactoryWorld(bad), InputError);
}

}  // namespace
}  // namespace arucoslam

namespace arucoslam {
namespace {

TEST(FactoryOptionsTest, CheckSaysWhichValueIsWrong) {
  FactoryOptions options;
  std::string why;
  EXPECT_TRUE(options.Check(&why)) << why;
  options.wall_marker_spacing_m = 0.5;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "wall_marker_spacing_m must be 0 or in [1, 20], is 0.5");
  options = {};
  options.aisles = 9;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_EQ(why, "aisles must be in [1, 8], is 9");
}

}  // namespace
}  // namespace arucoslam
