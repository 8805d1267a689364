// MarkerFrontend: each image's marker detection, run on a worker thread while the caller extracts
// features and searched where the previous frame's pose expects markers; then the frame located.
#pragma once

#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "arucoslam/map/frame.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/detector_regions.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/pipeline/marker_detector_worker.h"
#include "arucoslam/pipeline/system_report.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {

struct MarkerFrontendStats {
  TimingStats marker_ms;  // per located frame: detection and location
  // Per located frame: what it waited for its detections after extraction, plus location.
  TimingStats wait_ms;
  int num_full_scans = 0;  // images whose markers were searched in the whole image
};

// One image at a time, on the tracking thread: StartDetection, WaitForDetections (or
// AbandonDetection), Locate, RememberFrame. stats() may be read from any thread.
class MarkerFrontend {
 public:
  MarkerFrontend(const CameraModel& camera, const DetectorOptions& detector,
                 const MarkerSearchOptions& search);
  MarkerFrontend(const MarkerFrontend&) = delete;
  MarkerFrontend& operator=(const MarkerFrontend&) = delete;

  // Starts detecting in `grey` on the worker: around `markers` (the locating map) as seen from
  // the remembered pose, or in the whole image. `grey` stays unchanged until the detection is
  // waited for or abandoned.
  void StartDetection(const cv::Mat& grey, const MarkerMap& markers);
  // Blocks until the started detection is done; its time and the wait count toward the
  // frame's marker times (Locate).
  std::vector<MarkerDetection> WaitForDetections();
  // The caller failed meanwhile: the started detection is waited for and dropped, errors too.
  void AbandonDetection();
  // The frame's `detections` become its markers and `fusion` locates it in `markers` (the
  // locating map) with the map's `prediction`; `frame_index` is for the logs.
  void Locate(const std::vector<MarkerDetection>& detections, const MarkerMap& markers,
              const MapPrediction& prediction, std::size_t frame_index, Frame* frame,
              MarkerFusion* fusion);
  // After the frame: where the next image is searched. Its pose counts when in the marker
  // world (`report`: an aligned map's or a marker pose), else its marker location `fix`.
  void RememberFrame(const FrameReport& report, const std::optional<MarkerFix>& fix,
                     const std::vector<MarkerDetection>& detections);

  MarkerFrontendStats stats() const;

 private:
  MarkerDetector detector_;
  MarkerDetectorWorker worker_;  // runs detector_
  MarkerSearchPlanner search_;
  double detection_ms_ = 0.0;  // the current image's detection time
  double wait_ms_ = 0.0;       // the current image's wait for its detections
  mutable std::mutex stats_mutex_;
  MarkerFrontendStats stats_;
};

}  // namespace arucoslam
