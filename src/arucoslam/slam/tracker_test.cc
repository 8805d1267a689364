#include "arucoslam/slam/tracker.h"

#include <gtest/gtest.h>

#include <utility>

#include <algorithm>
#include <random>

#include "arucoslam/geometry/camera.h"

namespace arucoslam {
namespace {

CameraModel TestCamera() {
  return PinholeCamera(640, 480, 500.0);
}

// Points with random descriptors in front of a camera moving along world x with a slow yaw;
// each frame sees every point in its image (0.3 px noise, 3 flipped descriptor bits) plus
// 150 distractor keypoints with random descriptors.
class SyntheticWorld {
 public:
  explicit SyntheticWorld(std::uint32_t seed) : random_(seed) {
    std::uniform_real_distribution<double> x(-4.0, 6.0), y(-3.0, 3.0), z(4.0, 10.0);
    for (int j = 0; j < 1500; ++j) {
      points_.emplace_back(x(random_), y(random_), z(random_));
      descriptors_.push_back(RandomDescriptor());
    }
  }

  Rigid3 CamFromWorld(int t) const {
    const Rigid3 world_from_cam(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.004 * t, Eigen::Vector3d::UnitY())),
        Eigen::Vector3d(0.05 * t, 0.0, 0.002 * t));
    return world_from_cam.Inverse();
  }

  // Frame t; `truth_point` gets the world point index of each keypoint (-1: distractor).
  // `max_points`: only the first this many visible points are seen (a bland view).
  Frame MakeFrame(int t, std::vector<int>* truth_point, bool unrelated = false,
                  std::size_t max_points = 100000) {
    const CameraModel camera = TestCamera();
    const Rigid3 cam_from_world = CamFromWorld(t);
    std::normal_distribution<double> noise(0.0, 0.3);
    std::uniform_real_distribution<double> u(20.0, 620.0), v(20.0, 460.0);
    struct Entry {
      Eigen::Vector2d pixel;
      OrbDescriptor descriptor;
      int point;
    };
    std::vector<Entry> entries;
    for (std::size_t j = 0; j < points_.size() && !unrelated; ++j) {
      const auto pixel = camera.Project(cam_from_world * points_[j]);
      if (!pixel || !camera.InImage(*pixel, 20.0)) continue;
      if (entries.size() >= max_points) break;
      OrbDescriptor d = descriptors_[j];
      for (int flip = 0; flip < 3; ++flip) {
        const int bit = static_cast<int>(random_() % 256);
        d[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
      }
      entries.push_back(
          {*pixel + Eigen::Vector2d(noise(random_), noise(random_)), d, static_cast<int>(j)});
    }
    for (int k = 0; k < (unrelated ? 800 : 150); ++k) {
      entries.push_back({Eigen::Vector2d(u(random_), v(random_)), RandomDescriptor(), -1});
    }
    std::shuffle(entries.begin(), entries.end(), random_);
    Frame frame;
    frame.id = FrameId(t);
    frame.timestamp_s = 0.05 * t;
    frame.camera = camera;
    frame.features.pyramid = ScalePyramid::Make(8, 1.2);
    frame.features.image_width = camera.width;
    frame.features.image_height = camera.height;
    frame.features.descriptors =
        cv::Mat(static_cast<int>(entries.size()), kOrbDescriptorBytes, CV_8U);
    truth_point->clear();
    for (std::size_t i = 0; i < entries.size(); ++i) {
      cv::KeyPoint keypoint(static_cast<float>(entries[i].pixel.x()),
                            static_cast<float>(entries[i].pixel.y()), 31.0f, 0.0f);
      keypoint.octave = 0;
      frame.features.keypoints.push_back(keypoint);
      frame.features.undistorted.push_back(camera.Unproject(entries[i].pixel));
      std::copy(entries[i].descriptor.begin(), entries[i].descriptor.end(),
                frame.features.descriptors.ptr(static_cast<int>(i)));
      truth_point->push_back(entries[i].point);
    }
    frame.ResetMatches();
    return frame;
  }

  const std::vector<Eigen::Vector3d>& points() const { return points_; }

 private:
  OrbDescriptor RandomDescriptor() {
    OrbDescriptor d;
    for (auto& byte : d) byte = static_cast<std::uint8_t>(random_() & 0xff);
    return d;
  }

  std::mt19937 random_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<OrbDescriptor> descriptors_;
};

double PositionError(const Rigid3& a, const Rigid3& b) {
  return (a.Inverse().translation - b.Inverse().translation).norm();
}

// A map as initialisation would leave it: keyframes at frames 0 and 5 (true poses) and the
// points both see (true positions); returns the second keyframe and its frame.
KeyframeId BuildInitialMap(SyntheticWorld& world, Map& map, Frame* last_frame) {
  std::vector<int> truth0, truth5;
  Frame frame0 = world.MakeFrame(0, &truth0);
  Frame frame5 = world.MakeFrame(5, &truth5);
  frame0.cam_from_world = world.CamFromWorld(0);
  frame5.cam_from_world = world.CamFromWorld(5);
  return map.Write([&](MapData& data) {
    std::map<int, int> index_in_0;
    for (std::size_t i = 0; i < truth0.size(); ++i) {
      if (truth0[i] >= 0) index_in_0[truth0[i]] = static_cast<int>(i);
    }
    const KeyframeId k0 = data.AddKeyframe(Keyframe::FromFrame(frame0));
    const KeyframeId k5 = data.AddKeyframe(Keyframe::FromFrame(frame5));
    for (std::size_t i = 0; i < truth5.size(); ++i) {
      const auto it = index_in_0.find(truth5[i]);
      if (truth5[i] < 0 || it == index_in_0.end()) continue;
      MapPoint point;
      point.p_in_world = world.points()[truth5[i]];
      point.reference_keyframe = k5;
      const MapPointId id = data.AddMapPoint(point);
      data.AddObservation(k0, it->second, id);
      data.AddObservation(k5, static_cast<int>(i), id);
      data.UpdateDescriptor(id);
      data.UpdateNormalAndDepth(id);
      frame5.map_point_ids[i] = id;
    }
    *last_frame = frame5;
    return k5;
  });
}

TEST(TrackerTest, NotInitialisedGivesNoPose) {
  Map map;
  Tracker tracker(map);
  SyntheticWorld world(1);
  std::vector<int> truth;
  Frame frame = world.MakeFrame(0, &truth);
  const TrackingResult result = tracker.Track(frame);
  EXPECT_EQ(result.state, TrackingState::kNotInitialized);
  EXPECT_FALSE(frame.cam_from_world.has_value());
}

TEST(TrackerTest, TracksASequenceToTheTruth) {
  SyntheticWorld world(2);
  Map map;
  Frame start;
  const KeyframeId reference = BuildInitialMap(world, map, &start);
  ASSERT_GT(start.NumMatched(), 300);
  Tracker tracker(map);
  ASSERT_TRUE(TrackerOptions{}.Check());
  tracker.Start(start, reference);
  std::vector<int> truth;
  for (int t = 6; t <= 30; ++t) {
    Frame frame = world.MakeFrame(t, &truth);
    const TrackingResult result = tracker.Track(frame);
    ASSERT_EQ(result.state, TrackingState::kTracking) << "frame " << t;
    // No velocity before the first tracked frame: the reference keyframe path; then motion.
    EXPECT_EQ(result.method, t == 6 ? "reference" : "motion") << "frame " << t;
    ASSERT_TRUE(frame.cam_from_world.has_value());
    // Hundreds of exact points seen with 0.3 px noise: millimetres.
    EXPECT_LT(PositionError(*frame.cam_from_world, world.CamFromWorld(t)), 0.005) << t;
    EXPECT_LT(
        RotationAngle(frame.cam_from_world->rotation.conjugate() * world.CamFromWorld(t).rotation),
        0.001)
        << t;
    // Every match is right: keypoint -> the point it is a projection of.
    int wrong = 0, right = 0;
    map.Read([&](const MapData& data) {
      for (std::size_t i = 0; i < frame.map_point_ids.size(); ++i) {
        const MapPoint* point = data.FindMapPoint(frame.map_point_ids[i]);
        if (point == nullptr) continue;
        const bool same =
            truth[i] >= 0 && (point->p_in_world - world.points()[truth[i]]).norm() < 1e-12;
        (same ? right : wrong)++;
      }
    });
    EXPECT_EQ(wrong, 0) << "frame " << t;
    EXPECT_EQ(right, result.num_inliers);
    EXPECT_GT(result.num_inliers, 300);
  }
  // Velocity = one frame's motion.
  ASSERT_TRUE(tracker.velocity().has_value());
  const Rigid3 expected = world.CamFromWorld(30) * world.CamFromWorld(29).Inverse();
  EXPECT_LT((tracker.velocity()->translation - expected.translation).norm(), 0.005);
  // Tracking counted found/visible on the map points.
  const double found_ratio =
      map.Read([](const MapData& data) { return data.map_points().begin()->second.FoundRatio(); });
  EXPECT_GT(found_ratio, 0.5);
}

// A tracker with update_point_statistics off (the initialisation backfill's) tracks as well
// and leaves every point's visible/found counts as they were.
TEST(TrackerTest, TrackingWithoutPointStatisticsLeavesTheMapUntouched) {
  SyntheticWorld world(2);
  Map map;
  Frame start;
  const KeyframeId reference = BuildInitialMap(world, map, &start);
  const auto counts = [&] {
    return map.Read([](const MapData& data) {
      std::vector<std::pair<int, int>> all;
      for (const auto& [id, point] : data.map_points()) all.emplace_back(point.num_visible, point.num_found);
      return all;
    });
  };
  const auto before = counts();
  TrackerOptions options;
  options.update_point_statistics = false;
  Tracker tracker(map, options);
  tracker.Start(start, reference);
  std::vector<int> truth;
  for (int t = 6; t <= 12; ++t) {
    Frame frame = world.MakeFrame(t, &truth);
    ASSERT_EQ(tracker.Track(frame).state, TrackingState::kTracking) << "frame " << t;
    EXPECT_LT(PositionError(*frame.cam_from_world, world.CamFromWorld(t)), 0.005) << t;
  }
  EXPECT_EQ(counts(), before);
}

// One unrelated frame (a bland view) loses tracking; with recovery_frames the motion model
// keeps predicting and picks the next frame up, without it the reference keyframe does.
void LoseOneFrameAndRecover(int recovery_frames, const std::string& expected_method) {
  SCOPED_TRACE("recovery_frames " + std::to_string(recovery_frames));
  SyntheticWorld world(3);
  Map map;
  Frame start;
  const KeyframeId reference = BuildInitialMap(world, map, &start);
  TrackerOptions options;
  options.recovery_frames = recovery_frames;
  Tracker tracker(map, options);
  tracker.Start(start, reference);
  std::vector<int> truth;
  for (int t = 6; t <= 7; ++t) {
    Frame frame = world.MakeFrame(t, &truth);
    ASSERT_EQ(tracker.Track(frame).state, TrackingState::kTracking);
  }
  Frame unrelated = world.MakeFrame(8, &truth, true);
  const TrackingResult lost = tracker.Track(unrelated);
  EXPECT_EQ(lost.state, TrackingState::kLost);
  EXPECT_FALSE(unrelated.cam_from_world.has_value());
  EXPECT_EQ(tracker.velocity().has_value(), recovery_frames > 0);
  Frame again = world.MakeFrame(9, &truth);
  const TrackingResult recovered = tracker.Track(again);
  EXPECT_EQ(recovered.state, TrackingState::kTracking);
  EXPECT_EQ(recovered.method, expected_method);
  ASSERT_TRUE(again.cam_from_world.has_value());
  EXPECT_LT(PositionError(*again.cam_from_world, world.CamFromWorld(9)), 0.005);
  // The velocity is one frame's motion again, not the two frames since the last pose.
  ASSERT_TRUE(tracker.velocity().has_value());
  const Rigid3 expected = world.CamFromWorld(9) * world.CamFromWorld(8).Inverse();
  if (recovery_frames > 0) {
    EXPECT_LT((tracker.velocity()->translation - expected.translation).norm(), 0.005);
  }
}

// Frames missing from the stream (timestamps jump by ten periods): the motion model predicts
// over the elapsed time, tracks the next frame itself, and keeps one period's velocity.
TEST(TrackerTest, MotionModelPredictsOverMissingFrames) {
  SyntheticWorld world(4);
  Map map;
  Frame start;
  const KeyframeId reference = BuildInitialMap(world, map, &start);
  Tracker tracker(map);
  tracker.Start(start, reference);
  std::vector<int> truth;
  for (int t = 6; t <= 10; ++t) {
    Frame frame = world.MakeFrame(t, &truth);
    ASSERT_EQ(tracker.Track(frame).state, TrackingState::kTracking);
  }
  Frame after_gap = world.MakeFrame(20, &truth);
  const TrackingResult result = tracker.Track(after_gap);
  ASSERT_EQ(result.state, TrackingState::kTracking);
  EXPECT_EQ(result.method, "motion");
  ASSERT_TRUE(after_gap.cam_from_world.has_value());
  EXPECT_LT(PositionError(*after_gap.cam_from_world, world.CamFromWorld(20)), 0.005);
  const Rigid3 expected = world.CamFromWorld(20) * world.CamFromWorld(19).Inverse();
  ASSERT_TRUE(tracker.velocity().has_value());
  EXPECT_LT((tracker.velocity()->translation - expected.translation).norm(), 0.005);
  // A gap longer than max_prediction_gap_s: the reference keyframe, not the stale prediction.
  TrackerOptions options;
  options.max_prediction_gap_s = 0.2;
  Map map2;
  Frame start2;
  const KeyframeId reference2 = BuildInitialMap(world, map2, &start2);
  Tracker short_gaps(map2, options);
  short_gaps.Start(start2, reference2);
  for (int t = 6; t <= 10; ++t) {
    Frame frame = world.MakeFrame(t, &truth);
    ASSERT_EQ(short_gaps.Track(frame).state, TrackingState::kTracking);
  }
  Frame after_gap2 = world.MakeFrame(20, &truth);
  EXPECT_EQ(short_gaps.Track(after_gap2).method, "reference");
}

TEST(TrackerTest, LostOnAnUnrelatedFrameThenRecovers) {
  LoseOneFrameAndRecover(15, "motion");
  LoseOneFrameAndRecover(0, "reference");
}

// Three bland frames that see only 22 of the map's points (fewer than the 30 inliers
// min_local_map_inliers asks for): tracked because their poses agree with the motion model,
// to centimetres; with the weak path off (min_weak_inliers 30) the first of them is lost.
int TrackThroughSparseFrames(const TrackerOptions& options, double* worst_error) {
  SyntheticWorld world(4);
  Map map;
  Frame start;
  const KeyframeId reference = BuildInitialMap(world, map, &start);
  Tracker tracker(map, options);
  tracker.Start(start, reference);
  std::vector<int> truth;
  int tracked = 0;
  *worst_error = 0.0;
  for (int t = 6; t <= 12; ++t) {
    const bool sparse = t >= 9 && t <= 11;
    Frame frame = world.MakeFrame(t, &truth, false, sparse ? 22 : 100000);
    const TrackingResult result = tracker.Track(frame);
    if (result.state != TrackingState::kTracking) continue;
    ++tracked;
    *worst_error = std::max(*worst_error,
                            PositionError(*frame.cam_from_world, world.CamFromWorld(t)));
    if (sparse) EXPECT_LT(result.num_inliers, options.min_local_map_inliers) << t;
  }
  return tracked;
}

TEST(TrackerTest, WeakFramesAgreeingWithTheMotionModelAreTracked) {
  double worst = 0.0;
  EXPECT_EQ(TrackThroughSparseFrames(TrackerOptions{}, &worst), 7);
  EXPECT_LT(worst, 0.02);
  TrackerOptions strict;
  strict.min_weak_inliers = strict.min_local_map_inliers;
  EXPECT_LT(TrackThroughSparseFrames(strict, &worst), 7);
}

}  // namespace
}  // namespace arucoslam
