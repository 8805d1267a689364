// MapSession's initialisation backfill: the frames a monocular map needed to build up parallax
// (every frame since the first initialisation reference, also replaced references), and the
// frames the previous map lost before it was reset, are tracked backwards in time against the
// new map from the frame that initialised it.
#include <algorithm>
#include <utility>

#include "arucoslam/slam/map_session.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

void KeepAtMost(int max_frames, const Frame& frame, std::vector<Frame>* frames) {
  if (max_frames <= 0) return;
  frames->push_back(frame);
  if (static_cast<int>(frames->size()) > max_frames) frames->erase(frames->begin());
}

}  // namespace

void MapSession::KeepForBackfill(const Frame& frame) {
  KeepAtMost(options_.max_backfill_frames, frame, &initialisation_frames_);
}

void MapSession::KeepLostFrame(const Frame& frame) {
  KeepAtMost(options_.max_backfill_frames, frame, &lost_frames_);
}

std::vector<Frame> MapSession::TrackBackfill(Map& map, const TrackerOptions& tracking,
                                             const Frame& second, KeyframeId first_id,
                                             KeyframeId second_id) {
  std::vector<Frame> frames = std::move(initialisation_frames_);
  initialisation_frames_.clear();
  std::vector<Frame> tracked;
  if (frames.empty()) return tracked;
  // A replaced reference is kept when it is replaced, after the frames that followed it.
  std::stable_sort(frames.begin(), frames.end(),
                   [](const Frame& a, const Frame& b) { return a.timestamp_s < b.timestamp_s; });
  TrackerOptions backwards_options = tracking;
  backwards_options.update_point_statistics = false;  // the map stays exactly as it is
  Tracker backwards(map, backwards_options);
  backwards.Start(second, second_id);
  for (auto it = frames.rbegin(); it != frames.rend(); ++it) {
    Frame& frame = *it;
    frame.ResetMatches();
    frame.cam_from_world.reset();
    if (backwards.Track(frame).state != TrackingState::kTracking) break;
    backwards.SetReferenceKeyframe(first_id);
    tracked.push_back(std::move(frame));
  }
  ARUCOSLAM_LOG_DEBUG("initialisation backfill: {} of {} earlier frames tracked", tracked.size(),
                      frames.size());
  return tracked;
}

}  // namespace arucoslam
