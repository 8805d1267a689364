// CameraSource: a live camera (V4L2 device such as /dev/video0, through OpenCV videoio) as a
// FrameSource. A capture thread grabs frames as the camera delivers them and keeps at most
// `queue_capacity` for Next(); frames arriving while the queue is full are dropped and counted.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <memory>
#include <opencv2/videoio.hpp>
#include <optional>
#include <string>
#include <thread>

#include "arucoslam/io/frame_source.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct CameraSourceOptions {
  // Frames held for the consumer (>= 1); a slower consumer loses frames instead of lagging.
  // (A frame of another size than the first, after a device reset, is dropped too.)
  std::size_t queue_capacity = 2;
  // Capture ends once this flag is set (e.g. by a SIGINT handler); may be null.
  const std::atomic<bool>* stop = nullptr;
  // OpenCV capture backend: cv::CAP_V4L2 for devices, cv::CAP_ANY to let OpenCV choose.
  int api = cv::CAP_ANY;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("queue_capacity", queue_capacity, 1);
    return check.ok();
  }
};

class CameraSource : public FrameSource {
 public:
  // Opens `device` (a path such as /dev/video0, a camera index such as "0", or anything else
  // cv::VideoCapture opens), asks it for the camera's resolution, reads the first frame and
  // starts capturing. Throws InputError naming the device: cannot open, no frame, frames of
  // another size than the calibration's.
  CameraSource(const std::string& device, const CameraModel& camera,
               const CameraSourceOptions& options = {});
  // Stops and joins the capture thread.
  ~CameraSource() override;

  // Waits for the next captured frame; nullopt once capture has ended (stop flag, Stop(),
  // end of the stream or a device error) and the held frames are handed out. Timestamps are
  // seconds since the first frame, taken when the frame was grabbed.
  std::optional<SourceFrame> Next() override;
  const CameraModel& camera() const override { return camera_; }
  std::string layout() const override { return "camera"; }
  bool live() const override { return true; }
  std::size_t frames_dropped() const override { return dropped_.load(); }
  // Frames grabbed from the device so far (handed out, held or dropped).
  std::size_t frames_captured() const { return captured_.load(); }

  // Ends capture (any thread); Next() then hands out what is held and returns nullopt.
  void Stop() { stop_requested_ = true; }

 private:
  struct Queue;
  void Capture();

  std::string device_;
  CameraModel camera_;
  CameraSourceOptions options_;
  cv::VideoCapture capture_;
  std::chrono::steady_clock::time_point start_;
  std::unique_ptr<Queue> queue_;
  std::atomic<bool> stop_requested_{false};
  std::atomic<std::size_t> dropped_{0};
  std::atomic<std::size_t> captured_{0};
  std::size_t next_index_ = 0;
  std::thread thread_;
};

}  // namespace arucoslam
