#include "arucoslam/io/frame_source.h"

#include "arucoslam/io/calibration.h"
#include "arucoslam/io/video_source.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {

std::optional<SourceFrame> DatasetSource::Next() {
  if (next_ >= dataset_.size()) return std::nullopt;
  SourceFrame frame;
  frame.index = next_;
  frame.timestamp_s = dataset_.frame(next_).timestamp_s;
  frame.image = dataset_.LoadImage(next_);
  ++next_;
  return frame;
}

std::unique_ptr<FrameSource> OpenFrameSource(const std::filesystem::path& path,
                                             const DatasetOptions& options) {
  if (std::filesystem::is_regular_file(path)) {
    if (options.camera_path.empty()) {
      throw InputError(path.string(), "a video needs a camera calibration file (--camera)");
    }
    VideoSourceOptions video;
    video.rate_hz = options.rate_hz;
    return std::make_unique<VideoSource>(path, ReadCameraModel(options.camera_path), video);
  }
  return std::make_unique<DatasetSource>(Dataset::Open(path, options));
}

}  // namespace arucoslam
