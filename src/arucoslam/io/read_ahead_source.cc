#include "arucoslam/io/read_ahead_source.h"

#include <stdexcept>
#include <utility>

#include "arucoslam/io/frame_handoff.h"

namespace arucoslam {

ReadAheadSource::ReadAheadSource(std::unique_ptr<FrameSource> recorded,
                                 const ReadAheadOptions& options)
    : WrappingSource(std::move(recorded)) {
  std::string why;
  if (!options.Check(&why)) throw std::invalid_argument("ReadAheadOptions: " + why);
  frames_ = std::make_unique<FrameHandoff>(options.capacity);
}

ReadAheadSource::~ReadAheadSource() {
  frames_->Close();  // a reader waiting for room gives up
  if (thread_.joinable()) thread_.join();
}

void ReadAheadSource::Read() {
  try {
    while (std::optional<SourceFrame> frame = recorded().Next()) {
      if (!frames_->Push(std::move(*frame))) return;  // closed: the consumer is gone
    }
  } catch (...) {
    frames_->Fail(std::current_exception());
  }
  frames_->Close();
}

std::optional<SourceFrame> ReadAheadSource::Next() {
  if (!thread_.joinable()) thread_ = std::thread([this] { Read(); });
  return frames_->Take();
}

}  // namespace arucoslam
