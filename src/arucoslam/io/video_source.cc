#include "arucoslam/io/video_source.h"

#include <fmt/format.h>

#include <cmath>

#include "arucoslam/markers/preprocess.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

// Period used when the container gives no frame rate.
constexpr double kDefaultPeriodS = 1.0 / 30.0;

}  // namespace

VideoSource::VideoSource(const std::filesystem::path& path, const CameraModel& camera,
                         const VideoSourceOptions& options)
    : path_(path), camera_(camera), options_(options) {
  if (!options.Check()) throw InputError("--rate", "the frame rate must not be negative");
  RequireFile(path, "video file");
  if (!capture_.open(path.string(), cv::CAP_FFMPEG) || !capture_.isOpened()) {
    throw InputError(path.string(), "cannot open the video (not a video file, or corrupt)");
  }
  const double fps = capture_.get(cv::CAP_PROP_FPS);
  container_period_s_ = fps > 0.0 && std::isfinite(fps) ? 1.0 / fps : kDefaultPeriodS;
  const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
  if (count >= 1.0 && std::isfinite(count)) size_ = static_cast<std::size_t>(count);
  Decode();
  if (!pending_) throw InputError(path.string(), "the video has no decodable frames (corrupt?)");
}

void VideoSource::Decode() {
  pending_.reset();
  cv::Mat frame;
  if (!capture_.read(frame) || frame.empty()) return;
  SourceFrame out;
  out.index = next_index_;
  if (options_.rate_hz > 0.0) {
    out.timestamp_s = static_cast<double>(next_index_) / options_.rate_hz;
  } else {
    // The presentation time of the frame just decoded; a container without usable stamps
    // (missing or repeated) continues at its frame rate.
    out.timestamp_s = capture_.get(cv::CAP_PROP_POS_MSEC) * 1e-3;
    if (next_index_ > 0 && !(out.timestamp_s > last_timestamp_s_)) {
      out.timestamp_s = last_timestamp_s_ + container_period_s_;
    }
  }
  out.image = Preprocess(frame);  // 8-bit grey: colour converted, 16-bit scaled
  if (out.image.cols != camera_.width || out.image.rows != camera_.height) {
    throw InputError(
        path_.string(),
        fmt::format("frame {} is {}x{} but the camera calibration says {}x{}", next_index_,
                    out.image.cols, out.image.rows, camera_.width, camera_.height));
  }
  pending_ = std::move(out);
}

std::optional<SourceFrame> VideoSource::Next() {
  std::optional<SourceFrame> frame = std::move(pending_);
  if (!frame) return std::nullopt;
  ++next_index_;
  last_timestamp_s_ = frame->timestamp_s;
  Decode();
  return frame;
}

}  // namespace arucoslam
