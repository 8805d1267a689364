// MapSession's backfill on a synthetic point cloud: a camera moving sideways 5 cm per frame, a
// map initialised from frames 0 and 10, and the frames kept before it tracked backwards.
#include <gtest/gtest.h>

#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/slam/initializer.h"
#include "arucoslam/slam/map_initialization.h"
#include "arucoslam/slam/map_session.h"
#include "arucoslam/slam/synthetic_features.h"

namespace arucoslam {
namespace {

constexpr int kSecond = 10;  // the frame that initialises the map with frame 0

class BackfillScene {
 public:
  BackfillScene() : scene_(PinholeCamera(640, 480, 500.0)) {
    for (int t = 0; t <= kSecond; ++t) {
      const Rigid3 world_from_cam(Eigen::Quaterniond::Identity(),
                                  Eigen::Vector3d(0.05 * t, 0.0, 0.0));
      std::vector<int> truth;
      frames_.push_back(scene_.MakeFrame(FrameId(t), 0.05 * t, world_from_cam.Inverse(), &truth));
    }
  }

  const Frame& frame(int t) const { return frames_[t]; }

  // Initialises `map` from frames 0 and kSecond; false when the two views do not allow it.
  bool Initialize(Map& map) {
    first_ = frames_[0];
    second_ = frames_[kSecond];
    const InitializationResult two_view =
        Initializer().Initialize(first_.features, second_.features, scene_.camera());
    if (!two_view.success) return false;
    created_ = CreateInitialMap(map, first_, second_, two_view);
    return created_.success;
  }

  // Frames tracked by `session`'s backfill from the initialised map.
  std::vector<Frame> Backfill(MapSession& session, Map& map) const {
    return session.TrackBackfill(map, TrackerOptions(), second_, created_.first, created_.second);
  }

  // How far frame `t`'s tracked camera centre lies from where the straight, uniform motion
  // between the two keyframes puts it, as a fraction of their baseline.
  double OffPath(const Frame& tracked, int t) const {
    const Eigen::Vector3d c0 = first_.cam_from_world->Inverse().translation;
    const Eigen::Vector3d c1 = second_.cam_from_world->Inverse().translation;
    const Eigen::Vector3d expected = c0 + (c1 - c0) * (static_cast<double>(t) / kSecond);
    return (tracked.cam_from_world->Inverse().translation - expected).norm() / (c1 - c0).norm();
  }

 private:
  SyntheticFeatureScene scene_;
  std::vector<Frame> frames_;
  Frame first_, second_;
  InitialMapResult created_;
};

LostMapState LostByOldMap(bool fix) {
  LostMapState map;
  map.num_keyframes = 20;  // old enough to be kept while the loss lasts
  map.frame_has_marker_fix = fix;
  return map;
}

TEST(MapSessionBackfill, KeptFramesAreTrackedBackwardsNewestFirst) {
  BackfillScene scene;
  MapSession session({}, false);
  for (int t = 1; t < kSecond; ++t) session.KeepForBackfill(scene.frame(t));
  Map map;
  ASSERT_TRUE(scene.Initialize(map));
  const std::size_t points = map.NumMapPoints();
  const std::vector<Frame> tracked = scene.Backfill(session, map);
  ASSERT_EQ(tracked.size(), 9u);
  for (std::size_t i = 0; i < tracked.size(); ++i) {
    const int t = kSecond - 1 - static_cast<int>(i);
    EXPECT_DOUBLE_EQ(tracked[i].timestamp_s, scene.frame(t).timestamp_s);
    ASSERT_TRUE(tracked[i].cam_from_world.has_value());
    EXPECT_LT(scene.OffPath(tracked[i], t), 0.05) << "frame " << t;
  }
  EXPECT_EQ(map.NumMapPoints(), points);              // the map is left as it was
  EXPECT_TRUE(scene.Backfill(session, map).empty());  // the kept frames are used up
}

TEST(MapSessionBackfill, FramesLostBeforeAResetAreTriedByTheNextMap) {
  BackfillScene scene;
  MapSessionOptions options;
  options.max_backfill_frames = 6;
  MapSession session(options, false);
  for (int t = 1; t <= 4; ++t) {
    EXPECT_EQ(session.OnLostFrame(scene.frame(t), LostByOldMap(false)), LossAction::kKeep);
  }
  // A frame the markers located keeps its marker pose: not backfilled.
  EXPECT_EQ(session.OnLostFrame(scene.frame(5), LostByOldMap(true)), LossAction::kKeep);
  session.StartNewMap(std::nullopt);
  for (int t = 6; t < kSecond; ++t) session.KeepForBackfill(scene.frame(t));
  Map map;
  ASSERT_TRUE(scene.Initialize(map));
  const std::vector<Frame> tracked = scene.Backfill(session, map);
  // At most 6 frames, the newest: 9, 8, 7, 6, then the lost 4 and 3.
  std::vector<double> times;
  for (const Frame& frame : tracked) times.push_back(frame.timestamp_s);
  const std::vector<double> expected = {scene.frame(9).timestamp_s, scene.frame(8).timestamp_s,
                                        scene.frame(7).timestamp_s, scene.frame(6).timestamp_s,
                                        scene.frame(4).timestamp_s, scene.frame(3).timestamp_s};
  EXPECT_EQ(times, expected);
}

TEST(MapSessionBackfill, NoFramesKeptWithoutBackfill) {
  BackfillScene scene;
  MapSessionOptions options;
  options.max_backfill_frames = 0;
  MapSession session(options, false);
  for (int t = 1; t < kSecond; ++t) session.KeepForBackfill(scene.frame(t));
  Map map;
  ASSERT_TRUE(scene.Initialize(map));
  EXPECT_TRUE(scene.Backfill(session, map).empty());
}

}  // namespace
}  // namespace arucoslam
