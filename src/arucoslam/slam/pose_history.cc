#include "arucoslam/slam/pose_history.h"

#include <algorithm>
#include <iterator>
#include <set>
#include <utility>

namespace arucoslam {
namespace {

std::optional<Rigid3> KeyframePose(const Map& map, KeyframeId id) {
  return map.Read([&](const MapData& data) {
    const Keyframe* keyframe = data.FindKeyframe(id);
    return keyframe ? std::optional<Rigid3>(keyframe->cam_from_world) : std::nullopt;
  });
}

}  // namespace

PoseHistory::PoseHistory(bool keep_matches, KeyframeScale keyframe_scale)
    : keep_matches_(keep_matches), keyframe_scale_(std::move(keyframe_scale)) {}

double PoseHistory::ReferenceScale(KeyframeId reference) const {
  return keyframe_scale_ && reference.IsValid() ? keyframe_scale_(reference) : 1.0;
}

void PoseHistory::SortByTime() {
  std::stable_sort(poses_.begin(), poses_.end(), [](const TrackedPose& a, const TrackedPose& b) {
    return a.timestamp_s < b.timestamp_s;
  });
}

TrackedPose PoseHistory::MakePose(const Map& map, const Frame& frame, KeyframeId reference,
                                  bool world_aligned, const std::optional<MarkerFix>& fix) const {
  TrackedPose pose;
  pose.timestamp_s = frame.timestamp_s;
  pose.reference = reference;
  pose.cam_from_world = *frame.cam_from_world;
  pose.in_world = world_aligned;
  if (!world_aligned && fix) {
    pose.marker_cam_from_world = fix->world_from_cam.Inverse();
    pose.seen_markers = frame.markers;
  }
  const std::optional<Rigid3> reference_pose = KeyframePose(map, reference);
  if (!reference_pose) pose.reference = KeyframeId();
  pose.reference_scale = ReferenceScale(pose.reference);
  pose.cam_from_reference =
      reference_pose ? pose.cam_from_world * reference_pose->Inverse() : pose.cam_from_world;
  if (keep_matches_ && reference_pose) {
    for (std::size_t i = 0; i < frame.map_point_ids.size(); ++i) {
      if (!frame.map_point_ids[i].IsValid() || (i < frame.outliers.size() && frame.outliers[i])) {
        continue;
      }
      const int index = static_cast<int>(i);
      pose.matches.push_back({frame.map_point_ids[i], frame.UndistortedPixel(index).cast<float>(),
                              static_cast<float>(frame.SigmaPx(index))});
    }
    if (world_aligned && fix && fix->known_markers_only) pose.markers = fix->markers;
  }
  return pose;
}

void PoseHistory::Record(const Map& map, const Frame& frame, KeyframeId reference,
                         bool world_aligned, const std::optional<MarkerFix>& fix, bool in_place) {
  poses_.push_back(MakePose(map, frame, reference, world_aligned, fix));
  if (!in_place) return;
  for (std::size_t i = 0; i + 1 < poses_.size(); ++i) {
    if (poses_[i].timestamp_s == frame.timestamp_s) {
      poses_[i] = poses_.back();
      poses_.pop_back();
      break;
    }
  }
}

void PoseHistory::RecordMarkerPose(const Frame& frame, const Rigid3& cam_from_world) {
  TrackedPose pose;
  pose.timestamp_s = frame.timestamp_s;
  pose.cam_from_reference = cam_from_world;
  pose.cam_from_world = cam_from_world;
  pose.in_world = true;
  pose.seen_markers = frame.markers;
  poses_.push_back(pose);
}

int PoseHistory::MergeBackfill(const Map& map, const std::vector<Frame>& tracked,
                               KeyframeId reference, bool world_aligned,
                               const std::optional<MarkerFix>& fix) {
  std::vector<TrackedPose> merged;
  merged.reserve(poses_.size() + tracked.size());
  int num_replaced = 0;
  for (TrackedPose& pose : poses_) {
    const bool replaced = std::any_of(tracked.begin(), tracked.end(), [&](const Frame& frame) {
      return frame.timestamp_s == pose.timestamp_s;
    });
    if (replaced) {
      ++num_replaced;
    } else {
      merged.push_back(std::move(pose));
    }
  }
  for (const Frame& frame : tracked) {
    merged.push_back(MakePose(map, frame, reference, world_aligned, fix));
  }
  poses_ = std::move(merged);
  SortByTime();
  return num_replaced;
}

void PoseHistory::NoteUnposedMarkerFrame(double timestamp_s,
                                         const std::vector<MarkerObservation>& markers) {
  unposed_marker_frames_.push_back({timestamp_s, markers});
}

void PoseHistory::NoteUnposedWithoutMarkers(double timestamp_s) {
  unposed_without_markers_s_.push_back(timestamp_s);
}

int PoseHistory::CountUnposedWithoutMarkers(const std::vector<StampedPose>& trajectory) const {
  std::set<double> posed;
  for (const StampedPose& pose : trajectory) posed.insert(pose.timestamp_s);
  return static_cast<int>(
      std::count_if(unposed_without_markers_s_.begin(), unposed_without_markers_s_.end(),
                    [&](double timestamp_s) { return posed.count(timestamp_s) == 0; }));
}

Rigid3 PoseHistory::PoseFromReference(const TrackedPose& pose,
                                      const Rigid3& reference_cam_from_world) const {
  Rigid3 cam_from_reference = pose.cam_from_reference;
  cam_from_reference.translation *= ReferenceScale(pose.reference) / pose.reference_scale;
  return cam_from_reference * reference_cam_from_world;
}

std::vector<StampedPose> PoseHistory::CurrentMapPoses(const Map& map, bool world_only) const {
  std::vector<StampedPose> trajectory;
  map.Read([&](const MapData& data) {
    for (const TrackedPose& pose : poses_) {
      if (world_only && !pose.in_world) {
        if (pose.marker_cam_from_world) {
          trajectory.push_back({pose.timestamp_s, pose.marker_cam_from_world->Inverse()});
        }
        continue;
      }
      const Keyframe* reference = data.FindKeyframe(pose.reference);
      const Rigid3 cam_from_world =
          reference ? PoseFromReference(pose, reference->cam_from_world) : pose.cam_from_world;
      trajectory.push_back({pose.timestamp_s, cam_from_world.Inverse()});
    }
    return 0;
  });
  return trajectory;
}

void PoseHistory::ReanchorOrphans(const Map& map) {
  std::map<KeyframeId, Rigid3> now;
  map.Read([&](const MapData& data) {
    for (const auto& [id, keyframe] : data.keyframes()) now.emplace(id, keyframe.cam_from_world);
    return 0;
  });
  std::map<double, KeyframeId> by_time;
  for (TrackedPose& pose : poses_) {
    if (!pose.reference.IsValid() || now.count(pose.reference) != 0) continue;
    const auto last = keyframe_poses_.find(pose.reference);
    if (last == keyframe_poses_.end() || now.empty()) continue;
    if (by_time.empty()) {
      map.Read([&](const MapData& data) {
        for (const auto& [id, keyframe] : data.keyframes())
          by_time.emplace(keyframe.timestamp_s, id);
        return 0;
      });
    }
    auto nearest = by_time.lower_bound(pose.timestamp_s);
    if (nearest == by_time.end() ||
        (nearest != by_time.begin() &&
         pose.timestamp_s - std::prev(nearest)->first < nearest->first - pose.timestamp_s)) {
      nearest = std::prev(nearest);
    }
    const KeyframeId anchor = nearest->second;
    if (now.count(anchor) == 0) continue;
    pose.cam_from_world = PoseFromReference(pose, last->second);
    pose.reference = anchor;
    pose.reference_scale = ReferenceScale(anchor);
    pose.cam_from_reference = pose.cam_from_world * now.at(anchor).Inverse();
  }
  keyframe_poses_ = std::move(now);
}

void PoseHistory::RememberKeyframePoses(const Map& map) {
  keyframe_poses_.clear();
  map.Read([&](const MapData& data) {
    for (const auto& [id, keyframe] : data.keyframes()) {
      keyframe_poses_.emplace(id, keyframe.cam_from_world);
    }
    return 0;
  });
}

void PoseHistory::ForgetKeyframePoses() { keyframe_poses_.clear(); }

std::optional<Sim3> PoseHistory::LastPoseCorrection(const Map& map) const {
  if (poses_.empty()) return std::nullopt;
  const TrackedPose& last = poses_.back();
  const std::optional<Rigid3> reference = KeyframePose(map, last.reference);
  if (!reference) return std::nullopt;
  // The camera keeps its pose relative to its reference, its surroundings (and so its
  // velocity) scaled as the reference's.
  const Rigid3 cam_from_world_now = PoseFromReference(last, *reference);
  const double scale = ReferenceScale(last.reference) / last.reference_scale;
  return Sim3(cam_from_world_now.Inverse()) *
         Sim3(scale, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero()) *
         Sim3(last.cam_from_world);
}

void PoseHistory::Recalibrate(const CameraModel& before, const CameraModel& after) {
  const Eigen::Vector2d focal(before.fx, before.fy), centre(before.cx, before.cy);
  for (TrackedPose& pose : poses_) {
    for (FrameMatch& match : pose.matches) {
      const Eigen::Vector2d normalised =
          (match.pixel.cast<double>() - centre).cwiseQuotient(focal);
      const Eigen::Vector2d raw = before.Distort(normalised);
      match.pixel = (centre + focal.cwiseProduct(after.Unproject(raw))).cast<float>();
    }
  }
}

}  // namespace arucoslam
