#include "arucoslam/eval/map_accuracy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace arucoslam {
namespace {

SurfacePrimitive Box(const Rigid3& pose, const Eigen::Vector3d& size) {
  SurfacePrimitive p;
  p.shape = SurfaceShape::kBox;
  p.world_from_shape = pose;
  p.box_size = size;
  return p;
}

TEST(MapAccuracy, BoxDistanceOutsideInsideAndRotated) {
  const SurfacePrimitive box = Box(Rigid3(), Eigen::Vector3d(2.0, 4.0, 6.0));
  EXPECT_NEAR(DistanceToSurface(box, Eigen::Vector3d(1.5, 0, 0)), 0.5, 1e-15);           // face
  EXPECT_NEAR(DistanceToSurface(box, Eigen::Vector3d(2, 3, 0)), std::sqrt(2.0), 1e-15);  // edge
  EXPECT_NEAR(DistanceToSurface(box, Eigen::Vector3d(2, 3, 4)), std::sqrt(3.0), 1e-15);  // corner
  EXPECT_NEAR(DistanceToSurface(box, Eigen::Vector3d(0.2, 0, 0)), 0.8, 1e-15);           // inside
  EXPECT_NEAR(DistanceToSurface(box, Eigen::Vector3d(0, 1.9, 0)), 0.1, 1e-15);
  // Turned 90 degrees about z and moved: its 4 m side now lies along x.
  const SurfacePrimitive turned = Box(
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ())),
             Eigen::Vector3d(10, 0, 0)),
      Eigen::Vector3d(2.0, 4.0, 6.0));
  EXPECT_NEAR(DistanceToSurface(turned, Eigen::Vector3d(12.5, 0, 0)), 0.5, 1e-12);
  EXPECT_NEAR(DistanceToSurface(turned, Eigen::Vector3d(10, 1.25, 0)), 0.25, 1e-12);
}

TEST(MapAccuracy, PlaneAndCylinderDistances) {
  SurfacePrimitive plane;
  plane.shape = SurfaceShape::kPlane;
  plane.plane_size = Eigen::Vector2d(2.0, 2.0);
  EXPECT_NEAR(DistanceToSurface(plane, Eigen::Vector3d(0.5, 0.5, -0.3)), 0.3, 1e-15);
  EXPECT_NEAR(DistanceToSurface(plane, Eigen::Vector3d(4.0, 0.0, 4.0)), 5.0, 1e-15);
  plane.plane_size = Eigen::Vector2d::Zero();  // unbounded
  EXPECT_NEAR(DistanceToSurface(plane, Eigen::Vector3d(400.0, -7.0, 0.25)), 0.25, 1e-15);

  SurfacePrimitive cylinder;
  cylinder.shape = SurfaceShape::kCylinder;
  cylinder.radius = 1.0;
  cylinder.length = 4.0;
  cylinder.world_from_shape.translation = Eigen::Vector3d(0, 0, 2);  // standing on z = 0
  EXPECT_NEAR(DistanceToSurface(cylinder, Eigen::Vector3d(3, 0, 1)), 2.0, 1e-15);    // side
  EXPECT_NEAR(DistanceToSurface(cylinder, Eigen::Vector3d(0, 0, 5)), 1.0, 1e-15);    // cap
  EXPECT_NEAR(DistanceToSurface(cylinder, Eigen::Vector3d(4, 0, 8)), 5.0, 1e-15);    // rim
  EXPECT_NEAR(DistanceToSurface(cylinder, Eigen::Vector3d(0.7, 0, 2)), 0.3, 1e-15);  // inside
  EXPECT_NEAR(DistanceToSurface(cylinder, Eigen::Vector3d(0, 0, 0.1)), 0.1, 1e-15);  // by a cap
  EXPECT_EQ(DistanceToNearestSurface({}, Eigen::Vector3d::Zero()),
            std::numeric_limits<double>::infinity());
  EXPECT_NEAR(DistanceToNearestSurface({plane, cylinder}, Eigen::Vector3d(3, 0, 1)), 1.0, 1e-15);
}

TEST(MapAccuracy, StatisticsAfterTheTrajectoryAlignment) {
  // Floor z = 0; points in an estimate frame at half scale, shifted by 1 m in x.
  SurfacePrimitive floor;
  floor.shape = SurfaceShape::kPlane;
  const Sim3 gt_from_est(2.0, Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 0, 0));
  std::vector<Eigen::Vector3d> points;
  // World heights 0.0004 + 0.01 i (i = 0..9), away from the 5 cm threshold.
  for (int i = 0; i < 10; ++i) points.emplace_back(0.1 * i, 0.0, 0.0002 + 0.005 * i);
  const MapAccuracy accuracy = ComputeMapAccuracy(points, gt_from_est, {floor}, {});
  EXPECT_EQ(accuracy.num_points, 10u);
  EXPECT_NEAR(accuracy.median, 0.0454, 1e-12);
  EXPECT_NEAR(accuracy.percentile_90, 0.0814, 1e-12);  // position 8.1 of 0..9
  EXPECT_NEAR(accuracy.mean, 0.0454, 1e-12);
  EXPECT_NEAR(accuracy.fraction_within, 0.5, 1e-12);  // i = 0..4
  EXPECT_EQ(accuracy.inlier_distance, 0.05);
}

}  // namespace
}  // namespace arucoslam
