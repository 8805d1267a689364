// ReadAheadSource: a recorded source (dataset, video, bag) read a few frames ahead on its own
// thread, so that decoding the next images overlaps the SLAM's work on the current one.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "arucoslam/io/frame_source.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct ReadAheadOptions {
  std::size_t capacity = 4;  // frames decoded ahead of the consumer at most (>= 1)

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("capacity", capacity, 1);
    return check.ok();
  }
};

class FrameHandoff;

class ReadAheadSource : public WrappingSource {
 public:
  // Reading starts with the first Next(). Throws std::invalid_argument on options that fail
  // Check().
  explicit ReadAheadSource(std::unique_ptr<FrameSource> recorded,
                           const ReadAheadOptions& options = {});
  // Stops and joins the reading thread (frames read ahead are dropped).
  ~ReadAheadSource() override;
  ReadAheadSource(const ReadAheadSource&) = delete;
  ReadAheadSource& operator=(const ReadAheadSource&) = delete;

  // The recorded source's frames in its order; after the last, nullopt. What reading a frame
  // threw is rethrown in that frame's place, after the frames before it.
  std::optional<SourceFrame> Next() override;
  bool live() const override { return recorded().live(); }
  std::size_t frames_dropped() const override { return recorded().frames_dropped(); }

 private:
  void Read();

  std::unique_ptr<FrameHandoff> frames_;
  std::thread thread_;
};

}  // namespace arucoslam
