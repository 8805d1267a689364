#include "arucoslam/exe/experiments_floor_plan.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "arucoslam/util/error.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

class FloorPlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::ofstream(dir_ / "world.sdf") << R"(<?xml version="1.0"?><sdf version="1.9">
<world name="w"><model name="m"><static>true</static><link name="l">
  <visual name="rack"><pose>2 1 1 0 0 0</pose><geometry><box><size>3 0.5 2</size></box></geometry></visual>
  <visual name="pillar"><pose>5 0 1 0 0 0</pose>
    <geometry><cylinder><radius>0.2</radius><length>2</length></cylinder></geometry></visual>
</link></model></world></sdf>)";
  }

  ScratchFolder scratch_{"floor_plan"};
  const fs::path& dir_ = scratch_.path();
};

Trajectory Line(int n) {
  Trajectory trajectory;
  for (int i = 0; i < n; ++i) trajectory.Add(0.1 * i, Rigid3(Eigen::Quaterniond::Identity(),
                                                              Eigen::Vector3d(0.1 * i, 0.0, 0.6)));
  return trajectory;
}

TEST_F(FloorPlanTest, DrawsWorldTruthAndEachSlamRunWithItsKeyframes) {
  const Trajectory truth = Line(20);
  ExperimentRun slam;
  slam.label = "slam run";
  slam.keyframes = 2;
  slam.keyframe_poses = Line(2);
  slam.absolute.emplace();
  slam.absolute->aligned_est = truth;
  ExperimentRun markers_only;  // not a SLAM run: no trajectory of its own on the plan
  markers_only.label = "markers only";
  markers_only.absolute.emplace();
  const std::string svg = FloorPlanSvg(dir_ / "world.sdf", truth, {slam, markers_only});
  EXPECT_NE(svg.find("world (footprints)"), std::string::npos);
  EXPECT_NE(svg.find("ground truth"), std::string::npos);
  EXPECT_NE(svg.find("slam run"), std::string::npos);
  EXPECT_NE(svg.find("keyframes of slam run"), std::string::npos);
  EXPECT_EQ(svg.find("markers only"), std::string::npos);
}

TEST_F(FloorPlanTest, MissingWorldIsAnInputError) {
  EXPECT_THROW(FloorPlanSvg(dir_ / "none.sdf", Line(3), {}), InputError);
}

}  // namespace
}  // namespace arucoslam
