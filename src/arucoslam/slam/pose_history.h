// PoseHistory: every frame's pose from the start of a run, each held relative to its
// reference keyframe so that it follows the map's corrections, resets, merges and alignments.
// Synchronous: the caller holds whatever lock keeps the map and the history still.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "arucoslam/geometry/pose_consistency.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/geometry/sim3.h"
#include "arucoslam/map/map.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/optim/marker_pose_optimizer.h"
#include "arucoslam/optim/reprojection_error.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/tracked_pose.h"

namespace arucoslam {

// The final refinement of the tracked frames against the map (RefineAgainstMap).
struct FramePoseRefinement {
  // Keypoint and marker terms; keypoints.min_inliers is replaced per frame.
  MarkerPoseOptimizationOptions optimization;
  int min_inliers = 0;               // never fewer matched points than this
  double min_inlier_fraction = 0.0;  // nor fewer than this share of the frame's matches
};

// What RelocateInMarkerMap did.
struct MarkerRelocationCounts {
  int num_relocated = 0;  // marker-located poses located again
  int num_late = 0;       // frames that saw markers, posed only now
};

class PoseHistory {
 public:
  // How much closed loops scaled the map around a keyframe (1 when none).
  using KeyframeScale = std::function<double(KeyframeId)>;

  // `keep_matches`: recorded poses keep what tracking matched, for RefineAgainstMap.
  // `keyframe_scale`: may be empty (no loops close: every scale is 1).
  PoseHistory(bool keep_matches, KeyframeScale keyframe_scale);

  const std::vector<TrackedPose>& poses() const { return poses_; }

  // A frame's tracked pose against its reference keyframe in `map` (`world_aligned`: the map
  // is in the marker world; `fix`: the frame's marker location).
  TrackedPose MakePose(const Map& map, const Frame& frame, KeyframeId reference, bool world_aligned,
                       const std::optional<MarkerFix>& fix) const;
  // The same, added last; `in_place`: it takes the place of an earlier pose of the same frame
  // (a marker-only pose of a frame that later became a keyframe), keeping the time order.
  void Record(const Map& map, const Frame& frame, KeyframeId reference, bool world_aligned,
              const std::optional<MarkerFix>& fix, bool in_place = false);
  // A frame posed by its markers alone, in the world and tied to no keyframe.
  void RecordMarkerPose(const Frame& frame, const Rigid3& cam_from_world);
  // The calibration was refined from `before` to `after` (same intrinsics matrix): the kept
  // matches' undistorted pixels are undistorted again with `after`.
  void Recalibrate(const CameraModel& before, const CameraModel& after);
  // Frames tracked back in time from a new map's first keyframe (`reference`): each takes the
  // place of a marker-only pose of the same frame; time order is kept. Returns how many poses
  // were replaced.
  int MergeBackfill(const Map& map, const std::vector<Frame>& tracked, KeyframeId reference,
                    bool world_aligned, const std::optional<MarkerFix>& fix);
  // Frames without a pose: those that saw markers may be located at the end; those without
  // markers are counted (CountUnposedWithoutMarkers).
  void NoteUnposedMarkerFrame(double timestamp_s, const std::vector<MarkerObservation>& markers);
  void NoteUnposedWithoutMarkers(double timestamp_s);
  // The frames seen without pose nor marker that `trajectory` did not pose later either.
  int CountUnposedWithoutMarkers(const std::vector<StampedPose>& trajectory) const;

  // A pose from its reference keyframe's pose; the offset follows the scale changes that
  // loop corrections applied around the reference since the pose was recorded.
  Rigid3 PoseFromReference(const TrackedPose& pose, const Rigid3& reference_cam_from_world) const;
  // The poses in `map`'s frame (reference keyframes' current poses). `world_only`: only poses
  // in the world, plus the marker locations of poses outside it.
  std::vector<StampedPose> CurrentMapPoses(const Map& map, bool world_only) const;

  // Poses whose reference keyframe was culled since RememberKeyframePoses (or the previous
  // call) are re-anchored to the keyframe nearest in time, so that later corrections move
  // them too; then the keyframes' poses are remembered.
  void ReanchorOrphans(const Map& map);
  void RememberKeyframePoses(const Map& map);
  void ForgetKeyframePoses();
  // After the map was corrected: the similarity that carries the last pose as recorded to
  // where its reference keyframe puts it now (world_now_from_world_then, with the scale change
  // around the reference); nullopt without a last pose or its keyframe.
  std::optional<Sim3> LastPoseCorrection(const Map& map) const;
  // The map was aligned to the marker world by `world_from_map`: poses not in the world yet
  // move into it, and on a realignment (`realigned`) the poses tied to the map's keyframes
  // move with them, except those on `absorbed` keyframes (a merged map, already there).
  void MoveIntoWorld(const Sim3& world_from_map, bool realigned,
                     const std::set<KeyframeId>& absorbed);
  // Before `map` is replaced by an empty one: poses in the world stay, frozen at their current
  // estimate (a pose outside it at its marker location, if any; else it goes). `kept_for_merge`:
  // the map is kept for a merge, its poses remember their keyframe there.
  void FreezeForReset(const Map& map, bool kept_for_merge);
  // The closed map was merged into `map` with `ids`: its frozen poses follow their keyframes
  // again. Returns how many do.
  int FollowMergedMap(const Map& map, const AbsorbedIds& ids);

  // At the end: each pose of the current map optimised again against `map` (the points it
  // matched when tracked and its known markers); the matches are dropped. Returns how many.
  int RefineAgainstMap(const Map& map, const PinholeIntrinsics& intrinsics,
                       const FramePoseRefinement& refinement);
  // At the end, when `final_map` holds mapped markers: the poses located by markers are
  // located again in it, and the frames that saw markers but got no pose are located in it.
  // nullopt when no marker was mapped (nothing changes).
  std::optional<MarkerRelocationCounts> RelocateInMarkerMap(const MarkerMap& final_map,
                                                            const MarkerFusion& fusion);

 private:
  double ReferenceScale(KeyframeId reference) const;
  void SortByTime();

  bool keep_matches_;
  KeyframeScale keyframe_scale_;
  std::vector<TrackedPose> poses_;               // in time order
  std::map<KeyframeId, Rigid3> keyframe_poses_;  // as of ReanchorOrphans' previous call
  std::vector<UnposedMarkerFrame> unposed_marker_frames_;
  std::vector<double> unposed_without_markers_s_;  // frames seen without pose nor marker
};

}  // namespace arucoslam
