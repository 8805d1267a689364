#include "arucoslam/slam/keyframe_policy.h"

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool KeyframePolicyOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("min_frames_between", min_frames_between, 0);
  check.AtLeast("max_frames_between", max_frames_between, min_frames_between, "min_frames_between");
  check.InRange("tracked_ratio", tracked_ratio, 0.0, 1.0, Interval::kOpenClosed);
  check.AtLeast("min_observations", min_observations, 1);
  check.AtLeast("min_tracked_points", min_tracked_points, 0);
  check.AtLeast("weak_ratio", weak_ratio, 0.0);
  check.AtMost("weak_ratio", weak_ratio, tracked_ratio, "tracked_ratio");
  check.AtLeast("weak_tracked_points", weak_tracked_points, 0);
  check.AtLeast("weak_min_frames_between", weak_min_frames_between, 1);
  check.AtLeast("young_map_keyframes", young_map_keyframes, 0);
  return check.ok();
}

KeyframeDecision DecideKeyframe(const KeyframePolicyOptions& options,
                                const KeyframeDecisionInput& input) {
  if (input.num_tracked <= options.min_tracked_points) return {false, "too-few"};
  if (!MayInsertKeyframe(options, input)) return {false, "young-busy"};
  const bool ratio_low =
      input.num_tracked < options.tracked_ratio * input.num_reference_tracked;
  if (!ratio_low) return {false, "ratio-high"};
  const bool waited_long = input.frames_since_last_keyframe >= options.max_frames_between;
  const bool may_when_idle = input.frames_since_last_keyframe >= options.min_frames_between;
  if (input.mapper_idle && may_when_idle) return {true, "ratio"};
  const bool weak = input.num_tracked < options.weak_ratio * input.num_reference_tracked ||
                    input.num_tracked < options.weak_tracked_points;
  if (weak && input.frames_since_last_keyframe >= options.weak_min_frames_between &&
      input.mapper_has_room) {
    return {true, "weak"};
  }
  if (waited_long && input.mapper_has_room) return {true, "max-frames"};
  return {false, input.mapper_idle ? "too-soon" : "busy"};
}

bool MayInsertKeyframe(const KeyframePolicyOptions& options, const KeyframeDecisionInput& input) {
  return input.mapper_idle || input.num_map_keyframes > options.young_map_keyframes;
}

int ReferenceTrackedPoints(const MapData& data, KeyframeId keyframe, int min_observations) {
  const Keyframe* reference = data.FindKeyframe(keyframe);
  if (reference == nullptr) return 0;
  int count = 0;
  for (const MapPointId& id : reference->map_point_ids) {
    const MapPoint* point = data.FindMapPoint(id);
    if (point != nullptr && point->NumObservations() >= min_observations) ++count;
  }
  return count;
}

KeyframeId InsertKeyframe(Map& map, const Frame& frame, KeyframeId parent_hint) {
  Keyframe keyframe = Keyframe::FromFrame(frame);
  return map.Write([&](MapData& data) { return data.AddKeyframe(std::move(keyframe), parent_hint); });
}

}  // namespace arucoslam
