// System's initialisation backfill: the frames a monocular map needed to build up parallax
// (every frame since the first initialisation reference, also replaced references), and the
// frames the previous map lost before it was reset, get poses once the map exists, tracked
// backwards in time from the frame that initialised it.
#include <algorithm>
#include <utility>

#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {

namespace {

void KeepAtMost(int max_frames, const Frame& frame, std::vector<Frame>* frames) {
  if (max_frames <= 0) return;
  frames->push_back(frame);
  if (static_cast<int>(frames->size()) > max_frames) frames->erase(frames->begin());
}

}  // namespace

void System::KeepForBackfill(const std::optional<Frame>& frame) {
  const std::optional<Frame>& kept = frame ? frame : init_reference_;
  if (kept) KeepAtMost(options_.max_backfill_frames, *kept, &initialisation_frames_);
}

void System::KeepLostFrame(const Frame& frame) {
  // A frame the markers posed keeps that pose (in the world, whatever the next map does).
  if (!marker_fusion_.fix()) KeepAtMost(options_.max_backfill_frames, frame, &lost_frames_);
}

void System::BackfillInitialization(const Frame& second, KeyframeId first_id,
                                    KeyframeId second_id) {
  std::vector<Frame> frames = std::move(initialisation_frames_);
  initialisation_frames_.clear();
  if (frames.empty()) return;
  // A replaced reference is kept when it is replaced, after the frames that followed it.
  std::stable_sort(frames.begin(), frames.end(), [](const Frame& a, const Frame& b) {
    return a.timestamp_s < b.timestamp_s;
  });
  TrackerOptions tracking = options_.tracker;
  tracking.update_point_statistics = false;  // the map stays exactly as without the backfill
  Tracker backwards(*map_, tracking);
  backwards.Start(second, second_id);
  std::vector<TrackedPose> found;
  for (auto it = frames.rbegin(); it != frames.rend(); ++it) {
    Frame& frame = *it;
    frame.ResetMatches();
    frame.cam_from_world.reset();
    if (backwards.Track(frame).state != TrackingState::kTracking) break;
    backwards.SetReferenceKeyframe(first_id);
    RecordPose(frame, first_id);
    found.push_back(poses_.back());
    poses_.pop_back();
  }
  ARUCOSLAM_LOG_DEBUG("initialisation backfill: {} of {} earlier frames tracked", found.size(),
                      frames.size());
  if (found.empty()) return;
  // Marker-only poses of the same frames give way to the keypoint ones; time order is kept.
  std::vector<TrackedPose> merged;
  merged.reserve(poses_.size() + found.size());
  int num_replaced = 0;
  for (TrackedPose& pose : poses_) {
    const bool replaced = std::any_of(found.begin(), found.end(), [&](const TrackedPose& other) {
      return other.timestamp_s == pose.timestamp_s;
    });
    if (replaced) {
      ++num_replaced;
    } else {
      merged.push_back(std::move(pose));
    }
  }
  merged.insert(merged.end(), found.begin(), found.end());
  std::stable_sort(merged.begin(), merged.end(), [](const TrackedPose& a, const TrackedPose& b) {
    return a.timestamp_s < b.timestamp_s;
  });
  poses_ = std::move(merged);
  std::lock_guard lock(stats_mutex_);
  stats_.num_tracked += static_cast<int>(found.size()) - num_replaced;  // newly with a pose
}

}  // namespace arucoslam
