#include "arucoslam/io/read_ahead_source.h"

#include <stdexcept>
#include <utility>

#include "arucoslam/pipeline/bounded_queue.h"

namespace arucoslam {

struct ReadAheadSource::Queue {
  explicit Queue(std::size_t capacity) : frames(capacity) {}
  BoundedQueue<SourceFrame> frames;
};

ReadAheadSource::ReadAheadSource(std::unique_ptr<FrameSource> recorded,
                                 const ReadAheadOptions& options)
    : WrappingSource(std::move(recorded)) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("ReadAheadOptions: " + why);
  queue_ = std::make_unique<Queue>(options.capacity);
}

ReadAheadSource::~ReadAheadSource() {
  queue_->frames.Close();  // a reader waiting for room gives up
  if (thread_.joinable()) thread_.join();
}

void ReadAheadSource::Read() {
  try {
    while (std::optional<SourceFrame> frame = recorded().Next()) {
      if (!queue_->frames.Push(std::move(*frame))) return;  // closed: the consumer is gone
    }
  } catch (...) {
    std::lock_guard lock(error_mutex_);
    error_ = std::current_exception();
  }
  queue_->frames.Close();
}

std::optional<SourceFrame> ReadAheadSource::Next() {
  if (!thread_.joinable()) thread_ = std::thread([this] { Read(); });
  std::optional<SourceFrame> frame = queue_->frames.Pop();
  if (frame) return frame;
  std::lock_guard lock(error_mutex_);
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  return std::nullopt;
}

}  // namespace arucoslam
