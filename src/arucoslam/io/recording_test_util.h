// Test helper of io/: a recorded FrameSource of small synthetic frames, one of which may be
// unreadable, for the sources that wrap a recording (PacedSource, ReadAheadSource).
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "arucoslam/io/frame_source.h"
#include "arucoslam/util/error.h"

namespace arucoslam::testing_util {

// A recording of `count` small frames `interval_s` apart from t = 100 s; with `fail_at`, the
// frame of that index cannot be read (InputError, as a missing image).
class Recording : public FrameSource {
 public:
  Recording(std::size_t count, double interval_s, std::optional<std::size_t> fail_at = {})
      : count_(count), interval_s_(interval_s), fail_at_(fail_at) {
    camera_.width = 8;
    camera_.height = 6;
  }
  std::optional<SourceFrame> Next() override {
    if (next_ == count_) return std::nullopt;
    if (fail_at_ && next_ == *fail_at_) throw InputError("frame.png", "cannot be read");
    SourceFrame frame{next_, 100.0 + interval_s_ * static_cast<double>(next_),
                      cv::Mat(6, 8, CV_8UC1, cv::Scalar(static_cast<int>(next_)))};
    ++next_;
    return frame;
  }
  const CameraModel& camera() const override { return camera_; }
  std::string layout() const override { return "images"; }
  std::optional<std::size_t> size() const override { return count_; }

 private:
  std::size_t count_;
  double interval_s_;
  std::optional<std::size_t> fail_at_;
  std::size_t next_ = 0;
  CameraModel camera_;
};

}  // namespace arucoslam::testing_util
