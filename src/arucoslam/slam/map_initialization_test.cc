#include "arucoslam/slam/map_initialization.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/slam/synthetic_features.h"

namespace arucoslam {
namespace {

// Two views of a synthetic scene and a two-view result built from the true matches, with a
// motion whose baseline direction is 3 degrees off the truth and points triangulated for it.
struct TwoViews {
  Frame frame1, frame2;
  InitializationResult initialization;
  Rigid3 true_motion;
};

TwoViews MakeTwoViews() {
  const CameraModel camera = PinholeCamera(640, 480, 500.0);
  SyntheticFeatureScene scene(camera);
  TwoViews views;
  views.true_motion = Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY())),
                             Eigen::Vector3d(-0.4, 0.0, -0.05));
  std::vector<int> truth1, truth2;
  views.frame1 = scene.MakeFrame(FrameId(1), 0.0, Rigid3::Identity(), &truth1);
  views.frame2 = scene.MakeFrame(FrameId(2), 0.5, views.true_motion, &truth2);
  std::map<int, int> index2;
  for (std::size_t i = 0; i < truth2.size(); ++i) {
    if (truth2[i] >= 0) index2[truth2[i]] = static_cast<int>(i);
  }
  InitializationResult& init = views.initialization;
  init.success = true;
  init.cam2_from_cam1 = views.true_motion;
  init.cam2_from_cam1.translation =
      Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()) *
      views.true_motion.translation;
  for (std::size_t i = 0; i < truth1.size(); ++i) {
    const auto found = truth1[i] < 0 ? index2.end() : index2.find(truth1[i]);
    if (found == index2.end()) continue;
    init.matches.push_back({static_cast<int>(i), found->second, 0});
    init.points_in_cam1.push_back(scene.points()[truth1[i]]);
  }
  return views;
}

double BaselineAngleDeg(const Rigid3& a, const Rigid3& b) {
  const double cosine = a.translation.normalized().dot(b.translation.normalized());
  return std::acos(std::min(1.0, cosine)) * 180.0 / M_PI;
}

TEST(CreateInitialMapTest, RefinementMovesTheMotionUnlessItIsHeld) {
  for (const bool hold : {false, true}) {
    TwoViews views = MakeTwoViews();
    ASSERT_GT(views.initialization.matches.size(), 200u);
    Map map;
    InitialMapOptions options;
    options.hold_motion = hold;
    const InitialMapResult result =
        CreateInitialMap(map, views.frame1, views.frame2, views.initialization, options);
    ASSERT_TRUE(result.success) << result.message;
    const Rigid3 motion = *views.frame2.cam_from_world * views.frame1.cam_from_world->Inverse();
    const double to_truth = BaselineAngleDeg(motion, views.true_motion);
    const double to_given = BaselineAngleDeg(motion, views.initialization.cam2_from_cam1);
    if (hold) {
      EXPECT_LT(to_given, 1e-6) << "held motion moved";
    } else {
      EXPECT_LT(to_truth, 0.5) << "free refinement did not reach the true motion";
    }
  }
}

}  // namespace
}  // namespace arucoslam
