// Search regions for MarkerDetector::DetectInRegions: where markers are expected in a frame,
// from the known markers projected with a predicted camera pose and from earlier detections.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

using PixelQuad = std::array<Eigen::Vector2d, 4>;

// Pixels a region needs around a marker for DetectInRegions to find it as Detect does: the
// largest adaptive-threshold half window, the corner refinement's half window, OpenCV's
// distance to the border, and 2 more.
int MarkerRegionMargin(const DetectorOptions& options);

// The known markers' corners projected with `cam_from_world`, for markers wholly in front
// of the camera with their printed side towards it (others cannot be detected).
std::vector<PixelQuad> ProjectMarkerQuads(const MarkerMap& markers, const CameraModel& camera,
                                          const Rigid3& cam_from_world);

// One rectangle per quad: its bounding box grown on each side by `grow_rate` x the box's
// larger side + `margin_px` (+ extra_px[i] for quad i when given); rectangles that overlap
// are merged into their bounding box (again, until none overlap), then clipped to `image`.
// Rectangles wholly outside vanish.
std::vector<cv::Rect> SearchRegions(const std::vector<PixelQuad>& quads, cv::Size image,
                                    double grow_rate, int margin_px,
                                    const std::vector<double>& extra_px = {});

// Total area of non-overlapping rectangles over the image's area.
double AreaFraction(const std::vector<cv::Rect>& regions, cv::Size image);

struct MarkerSearchOptions {
  // The whole image is searched every this many frames (1: always), and whenever the
  // previous frame's pose is unknown; in between, regions around the markers projected with
  // that pose and around the previous frame's detections, grown by grow_rate x their size.
  int full_scan_interval = 15;
  double grow_rate = 0.5;
  // Projected markers' regions grow by this much more: the pose's error. Measured on the
  // default factory sequence: projections of a tracked (world-aligned) pose up to 50 px off.
  double pose_margin_px = 64.0;
  // Regions covering more of the image than this save little: the whole image is searched.
  double max_region_area = 0.5;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("full_scan_interval", full_scan_interval, 1);
    check.AtLeast("grow_rate", grow_rate, 0.0);
    check.AtLeast("pose_margin_px", pose_margin_px, 0.0);
    check.AtLeast("max_region_area", max_region_area, 0.0);
    return check.ok();
  }
};

// MarkerSearchPlanner: decides frame after frame where markers are searched (the whole image,
// or regions for MarkerDetector::DetectInRegions), from the previous frame's pose and markers.
class MarkerSearchPlanner {
 public:
  MarkerSearchPlanner(const CameraModel& camera, const DetectorOptions& detector,
                      const MarkerSearchOptions& options);

  // The next frame's regions, or nullopt for the whole image. `markers`: those expected in
  // the world whose frame Remember's poses are in.
  std::optional<std::vector<cv::Rect>> Next(const MarkerMap& markers);
  // After the frame: its cam_from_world in the markers' world when known, and its detections.
  void Remember(const std::optional<Rigid3>& cam_from_world,
                const std::vector<MarkerDetection>& detections);

  int num_full_scans() const { return num_full_scans_; }

 private:
  CameraModel camera_;
  int margin_px_;
  MarkerSearchOptions options_;
  std::optional<Rigid3> last_pose_;
  std::vector<PixelQuad> last_quads_;
  int frames_since_full_scan_ = 0;
  int num_full_scans_ = 0;
};

}  // namespace arucoslam
