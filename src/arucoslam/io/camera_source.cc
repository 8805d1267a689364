#include "arucoslam/io/camera_source.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <utility>

#include "arucoslam/markers/preprocess.h"
#include "arucoslam/pipeline/bounded_queue.h"
#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

// A camera index ("0") when `device` is one, else nullopt (a path or URL).
std::optional<int> CameraIndex(const std::string& device) {
  int index = 0;
  const auto [end, error] = std::from_chars(device.data(), device.data() + device.size(), index);
  if (device.empty() || error != std::errc() || end != device.data() + device.size()) {
    return std::nullopt;
  }
  return index;
}

}  // namespace

struct CameraSource::Queue {
  explicit Queue(std::size_t capacity) : frames(capacity) {}
  BoundedQueue<SourceFrame> frames;
};

CameraSource::CameraSource(const std::string& device, const CameraModel& camera,
                           const CameraSourceOptions& options)
    : device_(device), camera_(camera), options_(options) {
  if (!options.Check()) throw InputError(device, "the capture queue needs room for a frame");
  const std::optional<int> index = CameraIndex(device);
  const bool opened =
      index ? capture_.open(*index, options.api) : capture_.open(device, options.api);
  if (!opened || !capture_.isOpened()) {
    throw InputError(device, "cannot open the camera (no such device, busy, or not a camera)");
  }
  capture_.set(cv::CAP_PROP_FRAME_WIDTH, camera.width);
  capture_.set(cv::CAP_PROP_FRAME_HEIGHT, camera.height);
  cv::Mat first;
  if (!capture_.read(first) || first.empty()) {
    throw InputError(device, "the camera delivered no frame");
  }
  start_ = std::chrono::steady_clock::now();
  first = Preprocess(first);  // 8-bit grey: colour converted, 16-bit scaled
  if (first.cols != camera.width || first.rows != camera.height) {
    throw InputError(device, fmt::format("frames are {}x{} but the camera calibration says {}x{}",
                                         first.cols, first.rows, camera.width, camera.height));
  }
  queue_ = std::make_unique<Queue>(options.queue_capacity);
  queue_->frames.TryPush(SourceFrame{0, 0.0, first});
  captured_ = 1;
  thread_ = std::thread([this] { Capture(); });
}

CameraSource::~CameraSource() {
  Stop();
  queue_->frames.Close();
  if (thread_.joinable()) thread_.join();
}

void CameraSource::Capture() {
  const auto stopping = [this] {
    return stop_requested_.load() || (options_.stop != nullptr && options_.stop->load());
  };
  double last_timestamp_s = 0.0;
  while (!stopping()) {
    cv::Mat frame;
    if (!capture_.read(frame) || frame.empty()) break;  // end of stream or device gone
    // Strictly increasing even if the clock's tick is coarser than the frame interval.
    const double timestamp_s =
        std::max(std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(),
                 last_timestamp_s + 1e-6);
    last_timestamp_s = timestamp_s;
    ++captured_;
    cv::Mat grey = Preprocess(frame);
    if (grey.cols != camera_.width || grey.rows != camera_.height ||
        !queue_->frames.TryPush(SourceFrame{0, timestamp_s, std::move(grey)})) {
      ++dropped_;
    }
  }
  queue_->frames.Close();
}

std::optional<SourceFrame> CameraSource::Next() {
  std::optional<SourceFrame> frame = queue_->frames.Pop();
  if (frame) frame->index = next_index_++;
  return frame;
}

}  // namespace arucoslam
