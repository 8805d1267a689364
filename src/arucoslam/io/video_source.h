// VideoSource: the frames of a video file (OpenCV videoio, FFmpeg) as a FrameSource, converted
// to grey, with the container's presentation timestamps or a fixed rate.
#pragma once

#include <filesystem>
#include <memory>
#include <opencv2/videoio.hpp>
#include <optional>
#include <string>

#include "arucoslam/io/frame_source.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct VideoSourceOptions {
  // Frame rate in Hz that gives the timestamps (index / rate); 0: the container's timestamps.
  double rate_hz = 0.0;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("rate_hz", rate_hz, 0.0);
    return check.ok();
  }
};

class VideoSource : public FrameSource {
 public:
  // Opens the video and decodes its first frame. Throws InputError naming `path`: missing,
  // not a video or corrupt, no frames, frames of another size than `camera`'s.
  VideoSource(const std::filesystem::path& path, const CameraModel& camera,
              const VideoSourceOptions& options = {});

  std::optional<SourceFrame> Next() override;
  const CameraModel& camera() const override { return camera_; }
  std::string layout() const override { return "video"; }
  std::optional<std::size_t> size() const override { return size_; }

 private:
  // Decodes the next frame into pending_ (empty at the end of the stream).
  void Decode();

  std::filesystem::path path_;
  CameraModel camera_;
  VideoSourceOptions options_;
  cv::VideoCapture capture_;
  std::optional<std::size_t> size_;  // the container's frame count where it gives one
  double container_period_s_ = 0.0;  // 1 / the container's frame rate, else 1 / 30 s
  std::optional<SourceFrame> pending_;
  std::size_t next_index_ = 0;
  double last_timestamp_s_ = 0.0;
};

}  // namespace arucoslam
