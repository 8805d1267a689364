// PacedSource: replays a recorded source (dataset, video, bag) at the rate its timestamps give,
// as a live camera would deliver it; frames the consumer has no room for when due are dropped.
#pragma once

#include <atomic>
#include <cstddef>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "arucoslam/io/frame_source.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct PacedSourceOptions {
  // Frames held for the consumer (>= 1), as CameraSourceOptions::queue_capacity: a frame due
  // while this many wait is dropped.
  std::size_t queue_capacity = 2;
  // Replay speed: 1 plays the recording in its own time, 2 twice as fast.
  double speed = 1.0;
  // Replay ends once this flag is set (e.g. by a SIGINT handler); may be null.
  const std::atomic<bool>* stop = nullptr;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("queue_capacity", queue_capacity, 1);
    check.Above("speed", speed, 0.0);
    return check.ok();
  }
};

class PacedSource : public WrappingSource {
 public:
  // The replay starts with the first Next(): the first frame is due then, each next one when
  // its timestamp's offset from the first has elapsed (over `speed`). Throws
  // std::invalid_argument on options that fail Check().
  explicit PacedSource(std::unique_ptr<FrameSource> recorded, const PacedSourceOptions& options = {});
  // Stops and joins the replay thread.
  ~PacedSource() override;
  PacedSource(const PacedSource&) = delete;
  PacedSource& operator=(const PacedSource&) = delete;

  // Waits for the next frame handed over (the first call starts the replay); nullopt at the end of the recording (or on a stop
  // request) once the held frames are out. Rethrows what reading the recording threw.
  std::optional<SourceFrame> Next() override;
  bool live() const override { return true; }
  std::size_t frames_dropped() const override { return dropped_.load(); }

 private:
  struct Queue;
  void Replay();

  PacedSourceOptions options_;
  std::unique_ptr<Queue> queue_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<std::size_t> dropped_{0};
  std::size_t next_index_ = 0;
  std::thread thread_;
};

}  // namespace arucoslam
