#include "arucoslam/exe/marker_only_run.h"

#include <cstdio>

namespace arucoslam {

MarkerOnlyResult RunMarkerOnly(const Dataset& dataset, const MarkerMap& marker_map,
                               const MarkerOnlyOptions& options) {
  DetectorOptions detector_options = options.detector;
  detector_options.dictionary = marker_map.dictionary;
  const MarkerDetector detector(detector_options);
  MarkerOnlyResult result;
  result.frames = dataset.size();
  for (std::size_t i = 0; i < dataset.size(); ++i) {
    const cv::Mat image = dataset.LoadImage(i);
    Stopwatch detect_watch;
    const std::vector<MarkerDetection> detections =
        detector.Detect(Preprocess(image, options.preprocess));
    result.detection_ms.Add(detect_watch.ElapsedMilliseconds());
    bool any_known = false;
    for (const MarkerDetection& detection : detections) {
      any_known = any_known || marker_map.Find(detection.id) != nullptr;
    }
    if (any_known) {
      ++result.frames_with_markers;
      Stopwatch locate_watch;
      const CameraLocation location =
          LocateCamera(detections, marker_map, dataset.camera(), options.locator);
      result.locate_ms.Add(locate_watch.ElapsedMilliseconds());
      if (location.found && location.quality.ambiguous && options.skip_ambiguous) {
        ++result.ambiguous_skipped;
      } else if (location.found) {
        result.trajectory.Add(dataset.frame(i).timestamp_s, location.world_from_cam);
      }
    }
    if (options.progress && (i % 50 == 0 || i + 1 == dataset.size())) {
      std::fprintf(stderr, "\rmarkers only: frame %zu/%zu, %zu poses", i + 1, dataset.size(),
                   result.trajectory.size());
      if (i + 1 == dataset.size()) std::fprintf(stderr, "\n");
    }
  }
  return result;
}

}  // namespace arucoslam
