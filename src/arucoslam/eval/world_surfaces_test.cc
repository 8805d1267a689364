#include "arucoslam/eval/world_surfaces.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

TEST(WorldSurfaces, ConvertsEveryPrimitiveWithItsPose) {
  WorldModel world;
  WorldPrimitive box;
  box.type = ShapeType::kBox;
  box.world_from_shape.translation = Eigen::Vector3d(2, 0, 0.5);
  box.size = Eigen::Vector3d(1, 1, 1);
  WorldPrimitive plane;
  plane.type = ShapeType::kPlane;
  plane.size = Eigen::Vector3d(20, 10, 0);
  WorldPrimitive cylinder;
  cylinder.type = ShapeType::kCylinder;
  cylinder.world_from_shape.translation = Eigen::Vector3d(-3, 0, 1);
  cylinder.size = Eigen::Vector3d(0.6, 0.6, 2.0);  // radius 0.3, length 2
  world.primitives = {box, plane, cylinder};

  const std::vector<SurfacePrimitive> surfaces = SurfacesFromWorldModel(world);
  ASSERT_EQ(surfaces.size(), 3u);
  EXPECT_EQ(surfaces[0].shape, SurfaceShape::kBox);
  EXPECT_NEAR(DistanceToSurface(surfaces[0], Eigen::Vector3d(3.0, 0, 0.5)), 0.5, 1e-15);
  EXPECT_EQ(surfaces[1].shape, SurfaceShape::kPlane);
  EXPECT_NEAR(DistanceToSurface(surfaces[1], Eigen::Vector3d(0, 0, 0.3)), 0.3, 1e-15);
  EXPECT_NEAR(DistanceToSurface(surfaces[1], Eigen::Vector3d(13, 0, 0)), 3.0, 1e-15);
  EXPECT_EQ(surfaces[2].shape, SurfaceShape::kCylinder);
  EXPECT_DOUBLE_EQ(surfaces[2].radius, 0.3);
  EXPECT_NEAR(DistanceToSurface(surfaces[2], Eigen::Vector3d(-2, 0, 1)), 0.7, 1e-15);
}

TEST(WorldSurfaces, LoadsAnSdfWorld) {
  const std::string sdf = R"(<?xml version="1.0"?>
<sdf version="1.9">
  <world name="w">
    <model name="crate">
      <static>true</static>
      <pose>1 2 0.5 0 0 0</pose>
      <link name="link">
        <visual name="v">
          <geometry><box><size>1 1 1</size></box></geometry>
        </visual>
      </link>
    </model>
  </world>
</sdf>
)";
  const std::vector<SurfacePrimitive> surfaces =
      SurfacesFromWorldModel(LoadWorldModelFromString(sdf, "/tmp"));
  ASSERT_EQ(surfaces.size(), 1u);
  EXPECT_NEAR(DistanceToNearestSurface(surfaces, Eigen::Vector3d(1, 2, 2)), 1.0, 1e-12);
}

}  // namespace
}  // namespace arucoslam
