#include "arucoslam/pipeline/marker_detector_worker.h"

#include <stdexcept>
#include <utility>

#include "arucoslam/util/timing.h"

namespace arucoslam {

MarkerDetectorWorker::MarkerDetectorWorker(const MarkerDetector& detector)
    : detector_(detector), thread_([this] { Run(); }) {}

MarkerDetectorWorker::~MarkerDetectorWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void MarkerDetectorWorker::Start(const cv::Mat& image,
                                 std::optional<std::vector<cv::Rect>> regions) {
  {
    std::lock_guard lock(mutex_);
    if (started_) throw std::logic_error("MarkerDetectorWorker::Start before Wait");
    image_ = image;
    regions_ = std::move(regions);
    started_ = true;
    pending_ = true;
    done_ = false;
    error_ = nullptr;
  }
  changed_.notify_all();
}

TimedDetections MarkerDetectorWorker::Wait() {
  std::unique_lock lock(mutex_);
  if (!started_) throw std::logic_error("MarkerDetectorWorker::Wait without Start");
  changed_.wait(lock, [this] { return done_; });
  started_ = false;
  image_ = cv::Mat();
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  return std::move(result_);
}

void MarkerDetectorWorker::Run() {
  std::unique_lock lock(mutex_);
  while (true) {
    changed_.wait(lock, [this] { return stop_ || pending_; });
    if (!pending_) return;  // stopped with nothing to do
    pending_ = false;
    const cv::Mat image = image_;
    const std::optional<std::vector<cv::Rect>> regions = std::move(regions_);
    regions_.reset();
    lock.unlock();
    TimedDetections result;
    std::exception_ptr error;
    const Stopwatch wall;
    const double cpu_start = ThreadCpuMilliseconds();
    try {
      result.detections =
          regions ? detector_.DetectInRegions(image, *regions) : detector_.Detect(image);
    } catch (...) {
      error = std::current_exception();
    }
    result.cpu_ms = ThreadCpuMilliseconds() - cpu_start;
    result.wall_ms = wall.ElapsedMilliseconds();
    lock.lock();
    result_ = std::move(result);
    error_ = error;
    done_ = true;
    changed_.notify_all();
  }
}

}  // namespace arucoslam
