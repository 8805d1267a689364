#include "arucoslam/markers/detector_regions.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace arucoslam {

int MarkerRegionMargin(const DetectorOptions& options) {
  return options.adaptive_thresh_win_size_max / 2 +
         std::max(options.corner_refinement_win_size, options.min_distance_to_border) + 2;
}

std::vector<PixelQuad> ProjectMarkerQuads(const MarkerMap& markers, const CameraModel& camera,
                                          const Rigid3& cam_from_world) {
  const Eigen::Vector3d camera_in_world = cam_from_world.Inverse().translation;
  std::vector<PixelQuad> quads;
  for (const auto& [id, marker] : markers.markers) {
    if (!SeesPrintedSide(marker.world_from_marker, camera_in_world, 0.0)) continue;
    PixelQuad quad;
    bool in_front = true;
    const std::array<Eigen::Vector3d, 4> corners = marker.CornersInWorld();
    for (int k = 0; k < 4 && in_front; ++k) {
      const std::optional<Eigen::Vector2d> pixel = camera.Project(cam_from_world * corners[k]);
      in_front = pixel.has_value() && pixel->allFinite();
      if (in_front) quad[k] = *pixel;
    }
    if (in_front) quads.push_back(quad);
  }
  return quads;
}

std::vector<cv::Rect> SearchRegions(const std::vector<PixelQuad>& quads, cv::Size image,
                                    double grow_rate, int margin_px,
                                    const std::vector<double>& extra_px) {
  const cv::Rect whole(0, 0, image.width, image.height);
  std::vector<cv::Rect> regions;
  for (std::size_t i = 0; i < quads.size(); ++i) {
    const PixelQuad& quad = quads[i];
    Eigen::Vector2d low = quad[0], high = quad[0];
    for (const Eigen::Vector2d& corner : quad) {
      low = low.cwiseMin(corner);
      high = high.cwiseMax(corner);
    }
    // Far outside the image (or huge): the whole image bounds it.
    low = low.cwiseMax(Eigen::Vector2d(-4.0 * image.width, -4.0 * image.height));
    high = high.cwiseMin(Eigen::Vector2d(5.0 * image.width, 5.0 * image.height));
    const double grow = grow_rate * (high - low).maxCoeff() + margin_px +
                        (i < extra_px.size() ? extra_px[i] : 0.0);
    const int x0 = static_cast<int>(std::floor(low.x() - grow));
    const int y0 = static_cast<int>(std::floor(low.y() - grow));
    const int x1 = static_cast<int>(std::ceil(high.x() + grow)) + 1;
    const int y1 = static_cast<int>(std::ceil(high.y() + grow)) + 1;
    const cv::Rect region = cv::Rect(x0, y0, x1 - x0, y1 - y0);
    if ((region & whole).empty()) continue;
    regions.push_back(region);
  }
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < regions.size() && !merged; ++i) {
      for (std::size_t j = i + 1; j < regions.size() && !merged; ++j) {
        if ((regions[i] & regions[j]).empty()) continue;
        regions[i] |= regions[j];
        regions.erase(regions.begin() + static_cast<std::ptrdiff_t>(j));
        merged = true;
      }
    }
  }
  for (cv::Rect& region : regions) region &= whole;
  return regions;
}

double AreaFraction(const std::vector<cv::Rect>& regions, cv::Size image) {
  double area = 0.0;
  for (const cv::Rect& region : regions) area += region.area();
  return area / (static_cast<double>(image.width) * image.height);
}

MarkerSearchPlanner::MarkerSearchPlanner(const CameraModel& camera,
                                         const DetectorOptions& detector,
                                         const MarkerSearchOptions& options)
    : camera_(camera), margin_px_(MarkerRegionMargin(detector)), options_(options) {
  if (!options.Check()) throw std::invalid_argument("MarkerSearchPlanner: invalid options");
}

std::optional<std::vector<cv::Rect>> MarkerSearchPlanner::Next(const MarkerMap& markers) {
  if (last_pose_ && frames_since_full_scan_ + 1 < options_.full_scan_interval) {
    std::vector<PixelQuad> quads = ProjectMarkerQuads(markers, camera_, *last_pose_);
    std::vector<double> extra_px(quads.size(), options_.pose_margin_px);
    quads.insert(quads.end(), last_quads_.begin(), last_quads_.end());
    const cv::Size image(camera_.width, camera_.height);
    std::vector<cv::Rect> regions =
        SearchRegions(quads, image, options_.grow_rate, margin_px_, extra_px);
    if (AreaFraction(regions, image) <= options_.max_region_area) {
      ++frames_since_full_scan_;
      return regions;
    }
  }
  frames_since_full_scan_ = 0;
  ++num_full_scans_;
  return std::nullopt;
}

void MarkerSearchPlanner::Remember(const std::optional<Rigid3>& cam_from_world,
                                   const std::vector<MarkerDetection>& detections) {
  last_pose_ = cam_from_world;
  last_quads_.clear();
  for (const MarkerDetection& detection : detections) last_quads_.push_back(detection.corners);
}

}  // namespace arucoslam
