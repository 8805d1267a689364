// WorldRotationVote on one-marker views located by LocateCamera from noisy projected corners:
// a camera approaching markers on an end wall, its poses also given in a keypoint map's own
// frame (turned, scaled, shifted, with a slow rotation drift).
#include "arucoslam/slam/world_rotation_vote.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "arucoslam/geometry/sim3.h"
#include "arucoslam/markers/camera_locator.h"

namespace arucoslam {
namespace {

constexpr double kMarkerSize = 0.2;
constexpr double kNoisePx = 0.3;  // corner noise of rendered sequences

double Degrees(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return RotationAngle(a.inverse() * b) * 180.0 / M_PI;
}

// Three markers on the wall x = 10 m, facing back down the corridor (-x).
MarkerMap EndWall() {
  MarkerMap map;
  // Marker z (its normal, out of the front) along -x; marker x along -y, y along +z.
  Eigen::Matrix3d axes;
  axes.col(0) = -Eigen::Vector3d::UnitY();
  axes.col(1) = Eigen::Vector3d::UnitZ();
  axes.col(2) = -Eigen::Vector3d::UnitX();
  for (int id = 0; id < 3; ++id) {
    MarkerInfo info;
    info.id = id;
    info.size = kMarkerSize;
    info.world_from_marker =
        Rigid3(Eigen::Quaterniond(axes), Eigen::Vector3d(10.0, -1.5 + 1.5 * id, 1.2));
    map.markers[id] = info;
  }
  return map;
}

// Walking from x = 3 m towards the wall, weaving 0.8 m side to side and looking ahead
// (camera z along +x), turning with the weave.
Rigid3 WorldFromCam(int t) {
  const double x = 3.0 + 0.02 * t;
  const double y = 0.8 * std::sin(t / 25.0);
  Eigen::Matrix3d look;  // camera x = -world y, y = -world z, z = world x
  look.col(0) = -Eigen::Vector3d::UnitY();
  look.col(1) = -Eigen::Vector3d::UnitZ();
  look.col(2) = Eigen::Vector3d::UnitX();
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(-0.2 * std::cos(t / 25.0),
                                                 Eigen::Vector3d::UnitZ()));
  return Rigid3(yaw * Eigen::Quaterniond(look), Eigen::Vector3d(x, y, 1.2));
}

struct View {
  CameraLocation location;
  Rigid3 world_from_cam;  // truth
  Rigid3 cam_from_map;    // as a keypoint map tracks it
};

// The true world_from_map of the keypoint map below.
const Sim3& MapInWorld() {
  static const Sim3 world_from_map(
      0.37, Eigen::Quaterniond(Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(4.0, -2.0, 0.5));
  return world_from_map;
}

// Frames [first, last) each seeing one marker (id t / 40 % 3), with ambiguous locations only.
// The map's rotation drifts by `drift_deg_per_frame` about its vertical.
std::vector<View> AmbiguousViews(int first, int last, double drift_deg_per_frame,
                                 std::mt19937& rng, bool steady = false) {
  const MarkerMap map = EndWall();
  const CameraModel camera = PinholeCamera(640, 480, 500.0);
  std::normal_distribution<double> noise(0.0, kNoisePx);
  std::vector<View> views;
  for (int t = first; t < last; ++t) {
    const Rigid3 world_from_cam = WorldFromCam(steady ? first : t);
    const MarkerInfo& info = map.markers.at((t / 40) % 3);
    MarkerDetection detection;
    detection.id = info.id;
    const std::array<Eigen::Vector3d, 4> corners = info.CornersInWorld();
    bool visible = true;
    for (int c = 0; c < 4; ++c) {
      const std::optional<Eigen::Vector2d> pixel =
          camera.Project(world_from_cam.Inverse() * corners[c]);
      visible = visible && pixel && camera.InImage(*pixel, 5.0);
      if (pixel) detection.corners[c] = *pixel + Eigen::Vector2d(noise(rng), noise(rng));
    }
    if (!visible) continue;
    View view;
    view.location = LocateCamera({detection}, map, camera);
    if (!view.location.found || !view.location.quality.ambiguous ||
        !view.location.alternative_world_from_cam) {
      continue;
    }
    view.world_from_cam = world_from_cam;
    const Eigen::Quaterniond drift(
        Eigen::AngleAxisd(drift_deg_per_frame * (t - first) * M_PI / 180.0,
                          Eigen::Vector3d::UnitY()));
    const Rigid3 map_from_cam = MapInWorld().Inverse().TransformPose(world_from_cam);
    view.cam_from_map = map_from_cam.Inverse();
    view.cam_from_map.rotation = drift * view.cam_from_map.rotation;
    views.push_back(view);
  }
  return views;
}

TEST(WorldRotationVote, AmbiguousViewsAgreeOnTheMapRotation) {
  std::mt19937 rng(3);
  // 0.01 deg per frame: 2 degrees of drift over the 200 frames.
  const std::vector<View> views = AmbiguousViews(0, 200, 0.01, rng);
  ASSERT_GE(views.size(), 60u) << "the scene should give many ambiguous views";
  WorldRotationVote vote;
  std::size_t decided_after = 0;
  for (const View& view : views) {
    vote.Add(view.cam_from_map, view.location.world_from_cam,
             *view.location.alternative_world_from_cam);
    if (vote.WorldFromMap() && decided_after == 0) decided_after = vote.NumViews();
  }
  ASSERT_TRUE(vote.WorldFromMap().has_value());
  const double error_deg = Degrees(*vote.WorldFromMap(), MapInWorld().rotation);
  // Settle each view with the voted rotation and the map's orientation of the frame.
  int settled = 0, wrong = 0;
  for (const View& view : views) {
    const Eigen::Quaterniond predicted = *vote.WorldFromMap() * view.cam_from_map.rotation.inverse();
    AmbiguityPriorGates gates;
    gates.max_rotation_deg = 6.0;
    const AmbiguityChoice choice = ResolveAmbiguityByRotation(view.location, predicted, gates);
    if (choice == AmbiguityChoice::kNone) continue;
    ++settled;
    const Rigid3 chosen = *ChosenPose(view.location, choice);
    const Rigid3 other = choice == AmbiguityChoice::kBest ? *view.location.alternative_world_from_cam
                                                          : view.location.world_from_cam;
    wrong += Degrees(chosen.rotation, view.world_from_cam.rotation) >
             Degrees(other.rotation, view.world_from_cam.rotation);
  }
  std::printf("%zu ambiguous views, decided after %zu, map rotation off by %.2f deg, %d settled, "
              "%d wrongly\n", views.size(), decided_after, error_deg, settled, wrong);
  EXPECT_LT(error_deg, 2.0);
  EXPECT_GE(settled, static_cast<int>(views.size()) / 2);
  EXPECT_EQ(wrong, 0);
}

// A camera holding still sees one marker the same way in every frame: both solutions are
// as consistent as each other and nothing is decided.
TEST(WorldRotationVote, OneSteadyViewpointDecidesNothing) {
  std::mt19937 rng(4);
  const std::vector<View> views = AmbiguousViews(0, 40, 0.0, rng, /*steady=*/true);
  ASSERT_GE(views.size(), 20u);
  WorldRotationVote vote;
  for (const View& view : views) {
    vote.Add(view.cam_from_map, view.location.world_from_cam,
             *view.location.alternative_world_from_cam);
    EXPECT_FALSE(vote.WorldFromMap().has_value()) << "after " << vote.NumViews() << " views";
  }
}

TEST(WorldRotationVote, TooFewViewsAndClearDecideNothing) {
  std::mt19937 rng(5);
  const std::vector<View> views = AmbiguousViews(0, 200, 0.0, rng);
  WorldRotationVoteOptions options;
  WorldRotationVote vote(options);
  for (int i = 0; i + 1 < options.min_support; ++i) {
    vote.Add(views[i].cam_from_map, views[i].location.world_from_cam,
             *views[i].location.alternative_world_from_cam);
  }
  EXPECT_FALSE(vote.WorldFromMap().has_value());
  for (const View& view : views) {
    vote.Add(view.cam_from_map, view.location.world_from_cam,
             *view.location.alternative_world_from_cam);
  }
  EXPECT_TRUE(vote.WorldFromMap().has_value());
  EXPECT_EQ(vote.NumViews(), static_cast<std::size_t>(options.max_views));
  vote.Clear();
  EXPECT_FALSE(vote.WorldFromMap().has_value());
  EXPECT_EQ(vote.NumViews(), 0u);
  options.min_margin = 1.0;
  EXPECT_THROW(WorldRotationVote{options}, std::invalid_argument);
}

}  // namespace
}  // namespace arucoslam
