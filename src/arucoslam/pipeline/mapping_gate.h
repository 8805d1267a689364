// MappingGate: lets the tracking thread hold the mapping thread between two keyframes, to move
// the map while no keyframe is being mapped without waiting for the queued ones.
#pragma once

#include <condition_variable>
#include <mutex>

namespace arucoslam {

// The mapping thread brackets each keyframe with Enter and Leave; Hold returns once the
// keyframe in progress (if any) has left, and no keyframe enters until Release.
class MappingGate {
 public:
  // Mapping thread: waits while held, then marks a keyframe in progress.
  void Enter() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return !held_; });
    inside_ = true;
  }
  void Leave() {
    {
      std::lock_guard lock(mutex_);
      inside_ = false;
    }
    changed_.notify_all();
  }
  // Tracking thread: held once the keyframe in progress is finished.
  void Hold() {
    std::unique_lock lock(mutex_);
    held_ = true;
    changed_.wait(lock, [&] { return !inside_; });
  }
  // Whether a hold waits or is in force: the keyframe in progress should finish soon (a local
  // BA yields to it as to a queued keyframe).
  bool HoldRequested() const {
    std::lock_guard lock(mutex_);
    return held_;
  }
  void Release() {
    {
      std::lock_guard lock(mutex_);
      held_ = false;
    }
    changed_.notify_all();
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool held_ = false;    // no keyframe may enter
  bool inside_ = false;  // a keyframe is being mapped
};

}  // namespace arucoslam
