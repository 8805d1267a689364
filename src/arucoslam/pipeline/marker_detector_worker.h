// MarkerDetectorWorker: runs a MarkerDetector on a thread of its own, so a frame's marker
// detection overlaps other work on the caller's thread (System::ProcessImage: ORB extraction).
#pragma once

#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <opencv2/core.hpp>
#include <thread>
#include <vector>

#include "arucoslam/markers/detector.h"

namespace arucoslam {

// One detection's outcome and its cost.
struct TimedDetections {
  std::vector<MarkerDetection> detections;
  double wall_ms = 0.0;  // Detect's duration on the worker thread
  double cpu_ms = 0.0;   // CPU time of the worker thread during Detect (OpenCV's own pool
                         // threads, which detectMarkers uses, are not counted)
};

class MarkerDetectorWorker {
 public:
  // `detector` must outlive the worker.
  explicit MarkerDetectorWorker(const MarkerDetector& detector);
  ~MarkerDetectorWorker();  // finishes the running detection, then joins
  MarkerDetectorWorker(const MarkerDetectorWorker&) = delete;
  MarkerDetectorWorker& operator=(const MarkerDetectorWorker&) = delete;

  // Starts detecting in `image` (MarkerDetector::Detect), or only in `regions` of it when
  // given (MarkerDetector::DetectInRegions). The image is shared, not copied: the caller
  // leaves its pixels unchanged until Wait returns. One detection at a time: throws
  // std::logic_error when the previous one was not waited for.
  void Start(const cv::Mat& image,
             std::optional<std::vector<cv::Rect>> regions = std::nullopt);
  // Blocks until the started detection is done; rethrows what Detect threw. Throws
  // std::logic_error when nothing was started.
  TimedDetections Wait();

 private:
  void Run();

  const MarkerDetector& detector_;
  std::mutex mutex_;
  std::condition_variable changed_;
  cv::Mat image_;
  std::optional<std::vector<cv::Rect>> regions_;
  bool started_ = false;  // a detection was started and not yet waited for
  bool pending_ = false;  // the worker has not picked the started image up yet
  bool done_ = false;
  bool stop_ = false;
  TimedDetections result_;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace arucoslam
