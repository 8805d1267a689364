#include "arucoslam/sim/world_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "arucoslam/util/error.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

void WriteFile(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

class WorldModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // A 1x1 PNG is enough for path resolution (the loader does not decode it).
    WriteFile(dir_ / "crate" / "textures" / "wood.png", "png");
    WriteFile(dir_ / "crate" / "model.config",
              "<?xml version='1.0'?><model><name>crate</name><version>1.0</version>"
              "<sdf version='1.9'>model.sdf</sdf></model>");
    WriteFile(dir_ / "crate" / "model.sdf", R"(<?xml version="1.0"?>
<sdf version="1.9"><model name="crate"><static>true</static>
  <link name="body"><pose>0 0 0.5 0 0 0</pose>
    <visual name="box"><geometry><box><size>1 2 1</size></box></geometry>
      <material><diffuse>0.8 0.7 0.6 1</diffuse>
        <pbr><metal><albedo_map>textures/wood.png</albedo_map></metal></pbr></material>
    </visual></link></model></sdf>)");
  }

  fs::path WriteWorld(const std::string& models) {
    const fs::path path = dir_ / "world.sdf";
    WriteFile(path, "<?xml version=\"1.0\"?><sdf version=\"1.9\"><world name=\"w\">" + models +
                        "</world></sdf>");
    return path;
  }

  ScratchFolder scratch_{"world_model_test"};
  const fs::path& dir_ = scratch_.path();
};

TEST_F(WorldModelTest, ReadsPrimitivesWithComposedPoses) {
  const fs::path path = WriteWorld(R"(
    <include><uri>crate</uri><name>crate_a</name><pose>4 0 0 0 0 1.5707963267948966</pose></include>
    <model name="hall"><static>true</static><pose>1 2 0 0 0 0</pose>
      <link name="l"><pose>0 0 1 0 0 0</pose>
        <visual name="floor"><geometry><plane><normal>0 0 1</normal><size>10 20</size></plane></geometry></visual>
        <visual name="pillar"><pose>3 0 0 0 0 0</pose>
          <geometry><cylinder><radius>0.25</radius><length>2</length></cylinder></geometry>
          <material><diffuse>0.1 0.2 0.3 1</diffuse></material></visual>
        <visual name="wall"><geometry><plane><normal>1 0 0</normal><size>4 3</size></plane></geometry></visual>
      </link></model>)");
  const WorldModel world = LoadWorldModel(path);
  ASSERT_EQ(world.primitives.size(), 4u);
  const WorldPrimitive& box = world.primitives[0];
  EXPECT_EQ(box.type, ShapeType::kBox);
  EXPECT_EQ(box.name, "crate_a::body::box");
  EXPECT_NEAR((box.world_from_shape.translation - Eigen::Vector3d(4, 0, 0.5)).norm(), 0, 1e-12);
  // yaw 90 degrees: the box's x axis points along world y.
  EXPECT_NEAR((box.world_from_shape.rotation * Eigen::Vector3d::UnitX() -
               Eigen::Vector3d::UnitY()).norm(), 0, 1e-12);
  EXPECT_EQ(box.size, Eigen::Vector3d(1, 2, 1));
  EXPECT_EQ(box.texture, (dir_ / "crate" / "textures" / "wood.png").lexically_normal());
  EXPECT_NEAR(box.diffuse.x(), 0.8, 1e-6);
  const std::vector<fs::path> files = {(dir_ / "crate" / "model.sdf").lexically_normal(),
                                       (dir_ / "crate" / "model.config").lexically_normal(),
                                       (dir_ / "crate" / "textures" / "wood.png").lexically_normal()};
  EXPECT_EQ(world.files, files);

  const WorldPrimitive& floor = world.primitives[1];
  EXPECT_EQ(floor.type, ShapeType::kPlane);
  EXPECT_EQ(floor.size, Eigen::Vector3d(10, 20, 0));
  EXPECT_NEAR((floor.world_from_shape.translation - Eigen::Vector3d(1, 2, 1)).norm(), 0, 1e-12);
  EXPECT_TRUE(floor.texture.empty());

  const WorldPrimitive& pillar = world.primitives[2];
  EXPECT_EQ(pillar.type, ShapeType::kCylinder);
  EXPECT_DOUBLE_EQ(pillar.radius(), 0.25);
  EXPECT_DOUBLE_EQ(pillar.size.z(), 2.0);
  EXPECT_NEAR((pillar.world_from_shape.translation - Eigen::Vector3d(4, 2, 1)).norm(), 0, 1e-12);
  EXPECT_NEAR(pillar.diffuse.z(), 0.3, 1e-6);

  // The wall's normal (1 0 0) becomes the shape frame's +z.
  const WorldPrimitive& wall = world.primitives[3];
  EXPECT_NEAR((wall.world_from_shape.rotation * Eigen::Vector3d::UnitZ() -
               Eigen::Vector3d::UnitX()).norm(), 0, 1e-12);
}

TEST_F(WorldModelTest, DistanceToSurfaces) {
  const fs::path path = WriteWorld(R"(
    <model name="m"><static>true</static><link name="l">
      <visual name="b"><pose>0 0 1 0 0 0</pose><geometry><box><size>2 2 2</size></box></geometry></visual>
      <visual name="c"><pose>10 0 0 0 0 0</pose>
        <geometry><cylinder><radius>1</radius><length>4</length></cylinder></geometry></visual>
      <visual name="p"><pose>0 20 0 0 0 0</pose>
        <geometry><plane><normal>0 0 1</normal><size>2 2</size></plane></geometry></visual>
    </link></model>)");
  const WorldModel world = LoadWorldModel(path);
  ASSERT_EQ(world.primitives.size(), 3u);
  const auto& box = world.primitives[0];
  const auto& cylinder = world.primitives[1];
  const auto& plane = world.primitives[2];
  EXPECT_NEAR(DistanceToSurface(box, {0, 0, 3}), 1.0, 1e-12);        // above the top face
  EXPECT_NEAR(DistanceToSurface(box, {2, 2, 1}), std::sqrt(2.0), 1e-12);  // off an edge
  EXPECT_NEAR(DistanceToSurface(box, {0.5, 0, 1}), 0.5, 1e-12);      // inside
  EXPECT_NEAR(DistanceToSurface(cylinder, {12, 0, 0}), 1.0, 1e-12);
  EXPECT_NEAR(DistanceToSurface(cylinder, {10, 0, 1.5}), 0.5, 1e-12);  // inside, near a cap
  EXPECT_NEAR(DistanceToSurface(cylinder, {10, 0, 5}), 3.0, 1e-12);
  EXPECT_NEAR(DistanceToSurface(plane, {0.5, 20.5, -0.3}), 0.3, 1e-12);
  EXPECT_NEAR(DistanceToSurface(plane, {3, 20, 4}), std::sqrt(20.0), 1e-12);  // off an edge
  EXPECT_NEAR(DistanceToNearestSurface(world, {0, 0, 2.25}), 0.25, 1e-12);
  EXPECT_TRUE(std::isinf(DistanceToNearestSurface(WorldModel{}, {0, 0, 0})));
}

TEST_F(WorldModelTest, MissingFileIsInputError) {
  try {
    LoadWorldModel(dir_ / "absent.sdf");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(error.message().find("not found"), std::string::npos) << error.what();
  }
}

TEST_F(WorldModelTest, MalformedSdfGivesLibsdformatError) {
  const fs::path path = dir_ / "broken.sdf";
  WriteFile(path, "<?xml version='1.0'?><sdf version='1.9'><world name='w'><model name='m'>");
  try {
    LoadWorldModel(path);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), path.string());
    EXPECT_NE(error.message().find("not a readable SDF file"), std::string::npos)
        << error.what();
  }
}

TEST_F(WorldModelTest, MissingTextureIsInputError) {
  const fs::path path = WriteWorld(R"(<model name="m"><static>true</static><link name="l">
      <visual name="b"><geometry><box><size>1 1 1</size></box></geometry>
      <material><pbr><metal><albedo_map>nothere.png</albedo_map></metal></pbr></material>
      </visual></link></model>)");
  try {
    LoadWorldModel(path);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(error.message().find("nothere.png"), std::string::npos) << error.what();
  }
}

TEST_F(WorldModelTest, FileWithoutWorldIsInputError) {
  const fs::path path = dir_ / "model_only.sdf";
  WriteFile(path, R"(<?xml version="1.0"?><sdf version="1.9"><model name="m"><static>true</static>
    <link name="l"/></model></sdf>)");
  EXPECT_THROW(LoadWorldModel(path), InputError);
}

}  // namespace
}  // namespace arucoslam
