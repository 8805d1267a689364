#include "arucoslam/io/paced_source.h"

#include <chrono>
#include <condition_variable>
#include <stdexcept>
#include <utility>

#include "arucoslam/io/frame_handoff.h"

namespace arucoslam {

struct PacedSource::Queue {
  explicit Queue(std::size_t capacity) : frames(capacity) {}
  FrameHandoff frames;
  // Wakes the replay thread's wait for a frame's due time on a stop request.
  std::mutex wake_mutex;
  std::condition_variable wake;
};

PacedSource::PacedSource(std::unique_ptr<FrameSource> recorded, const PacedSourceOptions& options)
    : WrappingSource(std::move(recorded)), options_(options) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("PacedSourceOptions: " + why);
  queue_ = std::make_unique<Queue>(options.queue_capacity);
}

PacedSource::~PacedSource() {
  {
    std::lock_guard lock(queue_->wake_mutex);
    stop_requested_ = true;
  }
  queue_->wake.notify_all();
  queue_->frames.Close();
  if (thread_.joinable()) thread_.join();
}

void PacedSource::Replay() {
  using Clock = std::chrono::steady_clock;
  const auto stopping = [this] {
    return stop_requested_.load() || (options_.stop != nullptr && options_.stop->load());
  };
  const Clock::time_point start = Clock::now();
  std::optional<double> first_timestamp_s;
  try {
    while (!stopping()) {
      std::optional<SourceFrame> frame = recorded().Next();
      if (!frame) break;
      if (!first_timestamp_s) first_timestamp_s = frame->timestamp_s;
      const auto due = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                   (frame->timestamp_s - *first_timestamp_s) / options_.speed));
      {
        std::unique_lock lock(queue_->wake_mutex);
        // A stop flag set from outside (options_.stop) is seen within 50 ms.
        while (!stopping() && Clock::now() < due) {
          queue_->wake.wait_until(lock, std::min(due, Clock::now() + std::chrono::milliseconds(50)));
        }
      }
      if (stopping()) break;
      if (!queue_->frames.TryPush(std::move(*frame))) ++dropped_;
    }
  } catch (...) {
    queue_->frames.Fail(std::current_exception());
  }
  queue_->frames.Close();
}

std::optional<SourceFrame> PacedSource::Next() {
  if (!thread_.joinable()) thread_ = std::thread([this] { Replay(); });
  std::optional<SourceFrame> frame = queue_->frames.Take();
  if (frame) frame->index = next_index_++;
  return frame;
}

}  // namespace arucoslam
