// Internal to io/'s threaded sources (PacedSource, ReadAheadSource): the frames a reading
// thread hands to Next() through a bounded queue, and what reading threw, rethrown in its place.
#pragma once

#include <cstddef>
#include <exception>
#include <mutex>
#include <optional>
#include <utility>

#include "arucoslam/io/frame_source.h"
#include "arucoslam/pipeline/bounded_queue.h"

namespace arucoslam {

class FrameHandoff {
 public:
  explicit FrameHandoff(std::size_t capacity) : frames_(capacity) {}

  // Reading side: as BoundedQueue's Push and TryPush.
  bool Push(SourceFrame frame) { return frames_.Push(std::move(frame)); }
  bool TryPush(SourceFrame frame) { return frames_.TryPush(std::move(frame)); }
  // Reading side: what reading threw; Next() rethrows it after the frames queued before it.
  void Fail(std::exception_ptr error) {
    std::lock_guard lock(error_mutex_);
    error_ = std::move(error);
  }
  // No frame follows (the end, a failure, or the consumer gone).
  void Close() { frames_.Close(); }

  // Consumer side: the next frame (waits for it); nullopt once closed and drained, after
  // rethrowing a failure once.
  std::optional<SourceFrame> Take() {
    std::optional<SourceFrame> frame = frames_.Pop();
    if (frame) return frame;
    std::lock_guard lock(error_mutex_);
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    return std::nullopt;
  }

 private:
  BoundedQueue<SourceFrame> frames_;
  std::mutex error_mutex_;
  std::exception_ptr error_;
};

}  // namespace arucoslam
