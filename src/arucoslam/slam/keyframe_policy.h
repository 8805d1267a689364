// KeyframePolicy: decides whether a tracked frame becomes a keyframe (tracked-point ratio
// against the reference keyframe, frames since the last keyframe, local mapper busy).
#pragma once

#include <string>

#include "arucoslam/map/map.h"

namespace arucoslam {

struct KeyframePolicyOptions {
  // Frames that must pass after a keyframe before the next one may be inserted while the
  // local mapper is idle (0: the very next frame may be one). With 0 a blocking run made
  // nearly every frame a keyframe (546 inserted, 41 kept on the default route).
  int min_frames_between = 4;
  // After this many frames a keyframe is inserted even if the mapper is busy, provided its
  // queue has room (ORB-SLAM uses the frame rate: one second).
  int max_frames_between = 20;
  // Insert when the frame tracks fewer than this fraction of the points the reference
  // keyframe observes with at least `min_observations` observations (0.9 for monocular).
  double tracked_ratio = 0.9;
  // Points of the reference keyframe count when observed by at least this many keyframes
  // (2 while the map holds at most two keyframes).
  int min_observations = 3;
  // A frame tracking this many inliers or fewer never becomes a keyframe (unreliable pose).
  int min_tracked_points = 15;
  // Weak tracking (turns, bland views): fewer than weak_ratio x the reference's points or
  // fewer than weak_tracked_points inliers. Such a frame becomes a keyframe without waiting
  // for min_frames_between (and even with a busy mapper when its queue has room), so that new
  // points are triangulated before the old ones leave the view.
  double weak_ratio = 0.5;
  int weak_tracked_points = 100;
  // Frames that must pass between two weak keyframes. With 1 a turn made every frame a
  // keyframe: local BA's window (20 keyframes) then spanned 0.7 s of the turn, its fixed
  // keyframes too, and the scale drifted with the turn's low-parallax points.
  int weak_min_frames_between = 3;
  // While the map holds at most this many keyframes, no keyframe (of any kind) is inserted
  // while the mapper is busy: each new keyframe of a young map is tracked against a map whose
  // previous keyframe has been locally adjusted, so tracking need not wait for mapping.
  // 0: no such rule.
  int young_map_keyframes = 20;

  bool Check(std::string* why = nullptr) const;
};

// What the policy looks at for one tracked frame.
struct KeyframeDecisionInput {
  int frames_since_last_keyframe = 0;
  int num_tracked = 0;            // the frame's inlier matches to map points
  int num_reference_tracked = 0;  // ReferenceTrackedPoints() of its reference keyframe
  bool mapper_idle = true;        // nothing queued and nothing being processed
  bool mapper_has_room = true;    // the mapper's queue can take one more keyframe
  int num_map_keyframes = 0;      // keyframes in the map now
};

struct KeyframeDecision {
  bool insert = false;
  std::string reason;  // one word for logs: "ratio", "weak", "max-frames", "busy", "too-few", ...
};

KeyframeDecision DecideKeyframe(const KeyframePolicyOptions& options,
                                const KeyframeDecisionInput& input);

// False while a young map's mapper is busy (young_map_keyframes): then no keyframe at all,
// not even one the caller wants for other reasons (a marker anchor).
bool MayInsertKeyframe(const KeyframePolicyOptions& options, const KeyframeDecisionInput& input);

// Points of `keyframe` observed by at least `min_observations` keyframes (0 when unknown).
int ReferenceTrackedPoints(const MapData& data, KeyframeId keyframe, int min_observations);

// Stores a keyframe made from a tracked `frame` (its non-outlier matches become
// observations; covisibility edges and spanning-tree parent follow, `parent_hint` being the
// tracker's reference keyframe). Returns the new id.
KeyframeId InsertKeyframe(Map& map, const Frame& frame, KeyframeId parent_hint);

}  // namespace arucoslam
