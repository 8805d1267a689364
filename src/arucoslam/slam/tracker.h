// Tracker: estimates the pose of each new frame against the Map (constant-velocity motion
// model with projection search, reference-keyframe fallback, then the local map), synchronous.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/geometry/sim3.h"
#include "arucoslam/optim/marker_pose_optimizer.h"
#include "arucoslam/optim/pose_optimizer.h"

namespace arucoslam {

enum class TrackingState { kNotInitialized, kTracking, kLost };
std::string TrackingStateName(TrackingState state);

struct TrackerOptions {
  // Motion model: the last frame's points projected with the predicted pose; radius
  // base_radius_px x scale(level), so 15 px at level 0 (ORB-SLAM's monocular window).
  ProjectionMatchOptions motion_search{15.0, 1, 100, 0.9, true, {}};
  // Fewer matches than this: search again with twice the radius, then fall back.
  int min_motion_matches = 20;
  // After a loss the motion model keeps predicting (constant velocity from the last tracked
  // frame, search radius doubled) for this many frames, so that a short bland stretch (a
  // turn facing a plain wall) does not end tracking for good. 0: no such retry.
  int recovery_frames = 15;
  // Frames missing from the stream (dropped, or a gap in the recording) count as steps of the
  // motion model: it predicts over the time elapsed since the last tracked frame, in units of
  // the last frame period, for a gap up to this long; after a longer one the reference
  // keyframe is tried first. Seconds.
  double max_prediction_gap_s = 3.0;
  // Fallback: brute-force descriptor matching against the reference keyframe.
  BruteForceMatchOptions reference_search{64, 0.75, true, true, {}};
  int min_reference_matches = 15;
  // Local map: keyframes observing the frame's matched points plus up to this many best
  // covisible neighbours of each, at most max_local_keyframes in all.
  int covisible_per_keyframe = 10;
  int max_local_keyframes = 80;
  // Projection search of local points: radius base x (2.5 when viewed nearly head-on, else
  // 4) x scale(level), pixels.
  ProjectionMatchOptions local_map_search{1.0, 1, 100, 0.8, false, {}};
  // A point is searched only when its mean viewing direction and the current ray make an
  // angle with cosine at least this (60 degrees).
  double min_view_cos = 0.5;
  // Inliers needed after the first pose optimisation and after the local map.
  int min_pose_inliers = 10;
  int min_local_map_inliers = 30;
  // Weak views (a turn facing a bland wall): a frame with fewer inliers than
  // min_local_map_inliers but at least min_weak_inliers still counts as tracked when its pose
  // agrees with the motion model's prediction (rotation within weak_max_rotation_deg, camera
  // centre within weak_max_center_steps frame motions of it). The motion model is also
  // trusted alone: when the last frame's points give too few matches, the local map is
  // searched from the predicted pose with a window weak_radius_factor times wider.
  int min_weak_inliers = 15;
  double weak_max_rotation_deg = 2.0;
  double weak_max_center_steps = 2.0;
  double weak_radius_factor = 2.0;
  PoseOptimizationOptions pose;
  // Marker-corner residuals used with the keypoints when known markers are given to Track
  // (their keypoint part is `pose`, overwritten here).
  MarkerPoseOptimizationOptions marker_pose;
  // TrackFromPose: the keyframe nearest the given pose whose optical axis is within this
  // angle's cosine of the camera's (about 60 degrees) gives the points to project.
  double relocalization_min_axis_cos = 0.5;
  // Count each local-map search in the points' visible/found statistics (point culling
  // reads them). False for tracking that must leave the map untouched (initialisation backfill).
  bool update_point_statistics = true;

  bool Check(std::string* why = nullptr) const;
};

struct TrackingResult {
  TrackingState state = TrackingState::kNotInitialized;
  std::string method;  // "motion", "reference", "prediction", "pose" or "" when no pose
  int num_initial_matches = 0;
  int num_initial_inliers = 0;
  int num_local_map_matches = 0;  // matches added by the local-map search
  int num_inliers = 0;            // final inliers
};

class Tracker {
 public:
  Tracker(Map& map, const TrackerOptions& options = {});

  // After map initialisation (or relocalisation): `frame` has a pose and its matches;
  // `reference` is the keyframe made from it. Tracking continues from there.
  void Start(const Frame& frame, KeyframeId reference);
  // The keyframe most recently inserted becomes the reference for the fallback search.
  void SetReferenceKeyframe(KeyframeId reference) { reference_keyframe_ = reference; }
  // Forgets the pose history (state kNotInitialized).
  void Reset();

  // The caller found the last tracked pose wrong (e.g. markers contradict it): tracking
  // counts as lost and the motion model is dropped.
  void MarkLost();

  // Tracks `frame` (features with `undistorted` filled, camera set). On success fills
  // frame.cam_from_world and frame.map_point_ids (outlier matches removed).
  // `markers`: known (fixed) markers seen in the frame, in the map's world frame; when not
  // empty every pose optimisation uses their corners with the keypoints.
  TrackingResult Track(Frame& frame, const std::vector<MarkerPoseObservation>& markers = {});
  // Relocalisation from an outside pose (e.g. markers): the nearest keyframe's points are
  // projected with `cam_from_world`, matched, the pose optimised and the local map tracked.
  // On success tracking resumes (state kTracking); on failure the state is unchanged.
  TrackingResult TrackFromPose(Frame& frame, const Rigid3& cam_from_world,
                               const std::vector<MarkerPoseObservation>& markers = {});
  // After the map was moved by world_from_map (world alignment): the last pose and the
  // velocity are carried into the new frame and scale.
  void ApplySimilarity(const Sim3& world_from_map);

  TrackingState state() const { return state_; }
  KeyframeId reference_keyframe() const { return reference_keyframe_; }
  // cam_from_world(current) * world_from_cam(last) after the last successful frame.
  const std::optional<Rigid3>& velocity() const { return velocity_; }
  // The motion model's prediction of the pose of the frame taken at `timestamp_s`
  // (cam_from_world, the map's frame), as Track would use it; nullopt without a last tracked
  // pose and a velocity, or after a gap longer than max_prediction_gap_s.
  std::optional<Rigid3> PredictedPose(double timestamp_s) const {
    if (state_ == TrackingState::kNotInitialized || !last_frame_ ||
        !last_frame_->cam_from_world) {
      return std::nullopt;
    }
    const std::optional<int> steps = MotionSteps(timestamp_s);
    if (!steps) return std::nullopt;
    return Predict(*steps);
  }

 private:
  // Steps of the motion model to the frame taken at `timestamp_s`: the frames since the last
  // tracked one, or more when the time elapsed spans more frame periods (frames missing from
  // the stream); nullopt without a velocity or after a gap beyond max_prediction_gap_s.
  std::optional<int> MotionSteps(double timestamp_s) const;
  // `steps`: frames since the last tracked one (1 while tracking).
  bool TrackWithMotionModel(Frame& frame, TrackingResult& result, int steps);
  bool TrackReferenceKeyframe(Frame& frame, TrackingResult& result);
  // `radius_factor` widens the projection search (a pose predicted, not optimised);
  // `allow_weak`: min_weak_inliers suffice when the pose agrees with the motion model.
  bool TrackLocalMap(Frame& frame, TrackingResult& result, double radius_factor = 1.0,
                     bool allow_weak = true);
  // Tracks the local map from the motion model's prediction alone (few motion matches).
  bool TrackFromPrediction(Frame& frame, TrackingResult& result, int steps);
  // Whether a weakly tracked pose agrees with the motion model's prediction.
  bool AgreesWithPrediction(const Rigid3& cam_from_world, int steps) const;
  Rigid3 Predict(int steps) const;
  // Pose-only optimisation over the frame's matches from `initial`; drops outlier matches
  // and returns the number of inliers (0 when it failed).
  int OptimizeFramePose(Frame& frame, const Rigid3& initial);
  // The keyframe nearest `cam_from_world` facing about the same way (invalid when none).
  KeyframeId NearestKeyframe(const Rigid3& cam_from_world) const;

  Map& map_;
  TrackerOptions options_;
  TrackingState state_ = TrackingState::kNotInitialized;
  std::optional<Frame> last_frame_;
  std::optional<Rigid3> velocity_;
  int frames_lost_ = 0;  // frames since the last tracked one, while lost
  // Time per motion-model step at the last tracked frame (0: unknown).
  double frame_period_s_ = 0.0;
  KeyframeId reference_keyframe_;
  const std::vector<MarkerPoseObservation>* markers_ = nullptr;  // during Track only
};

}  // namespace arucoslam
