// MarkerFusion: each frame's marker detections made a usable camera location in the marker world
// (an ambiguous marker settled by predictions or votes), and the keypoint pose judged against it.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/pose_information.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/geometry/world_motion_prior.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/optim/marker_pose_optimizer.h"
#include "arucoslam/slam/covisible_marker_vote.h"
#include "arucoslam/slam/world_rotation_vote.h"

namespace arucoslam {

struct MarkerFusionOptions {
  CameraLocatorOptions locator;  // camera pose from the detected markers (LocateCamera)
  // A marker location is used only when it is not ambiguous (several markers, or one whose
  // IPPE solutions are well separated) and its corner RMS is at most this, pixels.
  double max_marker_rms_px = 2.0;
  // ... and when its nearest marker is at most this many marker sides from the camera: a
  // location's error grows with the square of the distance.
  double max_marker_distance_sides = 25.0;
  // An ambiguous one-marker location is still used when a prediction of the frame's world
  // pose (the aligned tracker's motion model, else constant velocity from the recent marker
  // fixes) settles it (ResolveAmbiguity, within ambiguity_gates).
  bool resolve_ambiguity_by_motion = true;
  AmbiguityPriorGates ambiguity_gates;  // how near a prediction the settled solution lies
  WorldMotionPriorOptions fix_motion;   // the constant-velocity prediction from the fixes
  // Before the map is aligned: the ambiguous one-marker views it tracked vote for the
  // world's orientation relative to the map (world_rotation_vote.h); once they agree, the
  // map's predicted orientation of a frame settles its ambiguous marker (rotation gate of
  // map_rotation_gates).
  bool resolve_ambiguity_by_map_rotation = true;
  WorldRotationVoteOptions rotation_vote;                           // that vote
  AmbiguityPriorGates map_rotation_gates{.max_rotation_deg = 6.0};  // its rotation gate
  // Else the markers the known map lacks, seen with the ambiguous one, vote: only the true
  // camera poses of two viewpoints put them at the same world points (covisible_marker_vote.h).
  bool resolve_ambiguity_by_covisible_markers = true;
  CovisibleMarkerVoteOptions covisible_vote;  // that vote
  // World-aligned map: a keypoint pose whose camera centre lies farther than this (metres)
  // from the same frame's marker location is wrong (a look-alike place), and a pose found
  // by relocalisation is confirmed only when it lies this close.
  double max_marker_disagreement_m = 0.5;

  bool Check(std::string* why = nullptr) const;
};

// A usable marker location of a frame.
struct MarkerFix {
  Rigid3 world_from_cam;
  std::vector<MarkerPoseObservation> markers;  // its inlier markers, undistorted corners
  bool known_markers_only = true;              // located by the known map's fixed markers alone
  bool settled_ambiguity = false;  // one ambiguous marker, settled by a prediction or vote
  // How firmly the markers' corners fix world_from_cam (MarkerLocationInformation); zero
  // when not computed.
  Matrix6d corner_information = Matrix6d::Zero();
};

// What the keypoint map tells MarkerFusion about the frame being located.
struct MapPrediction {
  bool world_aligned = false;  // the map is in the marker world
  bool tracking = false;       // its tracker follows the camera (state kTracking)
  // The tracker's motion-model pose of the frame (cam_from_world in the map's frame).
  std::optional<Rigid3> predicted_cam_from_map;
};

// What becomes of a tracked keypoint pose in a world-aligned map.
enum class PoseVerdict {
  kAccepted,  // no marker location, or one that agrees with the pose
  kRejected,  // contradicted: a look-alike place, the frame is lost
};

struct MarkerFusionStats {
  int num_located_frames = 0;                // frames with a usable marker location
  int num_disambiguations = 0;               // ... of which one ambiguous marker was settled
  int num_map_rotation_disambiguations = 0;  // ... by the unaligned map's voted orientation
  int num_covisible_disambiguations = 0;     // ... by the markers seen with it
  int num_rejected_poses = 0;                // keypoint poses rejected by the markers
};

class MarkerFusion {
 public:
  // `known`: the fixed marker map (markers.json); `unknown_marker_size_m`: the side given
  // to markers absent from it (UnknownMarkerSize).
  MarkerFusion(const MarkerFusionOptions& options, const CameraModel& camera,
               const MarkerMap& known, double unknown_marker_size_m);

  // Locates the frame at `timestamp_s` from its detections (distorted pixels) in `locating`
  // (the known markers plus those mapped so far); the result stays the current fix until the
  // next call. `frame_index` is for the logs.
  const std::optional<MarkerFix>& Locate(const std::vector<MarkerDetection>& detections,
                                         const MarkerMap& locating, double timestamp_s,
                                         const MapPrediction& map, std::size_t frame_index);
  // The current frame's usable location (nullopt: none) and how many known markers its
  // location rested on, usable or not.
  const std::optional<MarkerFix>& fix() const { return fix_; }
  int num_markers() const { return num_markers_; }

  // True when the current fix puts the camera within max_marker_disagreement_m of
  // `cam_from_world` (a relocalisation it confirms).
  bool Confirms(const Rigid3& cam_from_world) const;
  // The tracked pose of the current frame (`frame.cam_from_world` set) judged against the
  // current fix; without `world_aligned` every pose is accepted.
  PoseVerdict JudgeTrackedPose(const Frame& frame, bool world_aligned, std::size_t frame_index);
  // After a tracked (or relocalised) frame of a map not yet in the world: its ambiguous
  // marker votes for the world's orientation relative to the map.
  void NoteTrackedFrame(const Frame& frame, bool world_aligned);

  // The map was aligned to the world: its orientation votes are done with.
  void MapEnteredWorld();
  // The map was discarded: what was learnt about it is forgotten (the fixes' motion stays).
  void MapReset();

  // The camera pose (cam_from_world) from `markers` in `map` alone; an ambiguous location
  // takes the solution near `previous_cam_from_world` and without one is not used.
  std::optional<Rigid3> LocateInMap(const std::vector<MarkerObservation>& markers,
                                    const MarkerMap& map,
                                    const std::optional<Rigid3>& previous_cam_from_world) const;

  const MarkerFusionStats& stats() const { return stats_; }

 private:
  // Whether a found location (its IPPE alternative when `alternative`) fits its corners
  // within max_marker_rms_px with its nearest marker within max_marker_distance_sides
  // (returned in `nearest_sides`).
  bool UsableLocation(const CameraLocation& location, bool alternative, const MarkerMap& map,
                      double* nearest_sides) const;
  // The solution of an ambiguous one-marker location that the motion predictions settle on.
  // `by_map_rotation`: settled by the unaligned map's voted orientation alone.
  AmbiguityChoice ResolveByMotion(const CameraLocation& location, double timestamp_s,
                                  const MapPrediction& map, bool* by_map_rotation) const;
  // The location's pose as a fix, with its inlier markers' corners undistorted.
  MarkerFix MakeFix(const CameraLocation& location, const Rigid3& world_from_cam,
                    const std::vector<MarkerDetection>& detections,
                    const MarkerMap& locating) const;
  // The current fix's camera centre minus that of `cam_from_world` (needs fix_).
  Eigen::Vector3d MarkerOffset(const Rigid3& cam_from_world) const;
  bool Contradicts(const Rigid3& cam_from_world) const;

  MarkerFusionOptions options_;
  CameraModel camera_;
  std::vector<int> fixed_marker_ids_;  // the known map's fixed markers, ascending
  double unknown_marker_size_m_ = 0.0;

  std::optional<MarkerFix> fix_;  // the current frame's
  int num_markers_ = 0;
  WorldMotionPrior fix_motion_;  // the recent fixes' world poses
  // Unaligned map: the orientation votes of its ambiguous marker views, and the current
  // frame's ambiguous location (voted once the frame is tracked).
  WorldRotationVote rotation_vote_;
  CovisibleMarkerVote covisible_vote_;
  std::optional<CameraLocation> ambiguous_location_;
  MarkerFusionStats stats_;
};

}  // namespace arucoslam
