#include "arucoslam/markers/detector.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "arucoslam/markers/dictionary.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

Eigen::Vector2d MarkerDetection::Center() const {
  return 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
}

double MarkerDetection::Perimeter() const {
  double perimeter = 0.0;
  for (int i = 0; i < 4; ++i) perimeter += (corners[(i + 1) % 4] - corners[i]).norm();
  return perimeter;
}

bool DetectorOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Rule(IsDictionaryName(dictionary), "dictionary", dictionary, "a dictionary name");
  check.AtLeast("adaptive_thresh_win_size_min", adaptive_thresh_win_size_min, 3);
  check.AtLeast("adaptive_thresh_win_size_max", adaptive_thresh_win_size_max,
                adaptive_thresh_win_size_min, "adaptive_thresh_win_size_min");
  check.Above("adaptive_thresh_win_size_step", adaptive_thresh_win_size_step, 0);
  check.Above("min_marker_perimeter_rate", min_marker_perimeter_rate, 0.0);
  check.Above("max_marker_perimeter_rate", max_marker_perimeter_rate, min_marker_perimeter_rate,
              "min_marker_perimeter_rate");
  check.Above("polygonal_approx_accuracy_rate", polygonal_approx_accuracy_rate, 0.0);
  check.AtLeast("min_corner_distance_rate", min_corner_distance_rate, 0.0);
  check.AtLeast("min_distance_to_border", min_distance_to_border, 0);
  check.AtLeast("min_marker_distance_rate", min_marker_distance_rate, 0.0);
  check.AtLeast("corner_refinement_win_size", corner_refinement_win_size, 2);
  check.Above("corner_refinement_window_cells", corner_refinement_window_cells, 0.0);
  check.AtLeast("corner_refinement_max_iterations", corner_refinement_max_iterations, 1);
  check.Above("corner_refinement_min_accuracy", corner_refinement_min_accuracy, 0.0);
  check.AtLeast("perspective_remove_pixel_per_cell", perspective_remove_pixel_per_cell, 1);
  check.InRange("perspective_remove_ignored_margin_per_cell",
                perspective_remove_ignored_margin_per_cell, 0.0, 0.5, Interval::kClosedOpen);
  check.AtLeast("max_erroneous_bits_in_border_rate", max_erroneous_bits_in_border_rate, 0.0);
  check.AtLeast("min_otsu_std_dev", min_otsu_std_dev, 0.0);
  check.InRange("error_correction_rate", error_correction_rate, 0.0, 1.0, Interval::kClosed);
  check.AtLeast("dedup_distance_rate", dedup_distance_rate, 0.0);
  check.AtLeast("marker_border_bits", marker_border_bits, 1);
  check.Rule(april_tag_quad_decimate == 0.0 || april_tag_quad_decimate >= 1.0,
             "april_tag_quad_decimate", april_tag_quad_decimate, "0 or >= 1");
  check.AtLeast("april_tag_quad_sigma", april_tag_quad_sigma, 0.0);
  check.InRange("upsample", upsample, 1.0, 8.0, Interval::kClosed);
  check.Nested("rescue", rescue);
  check.Nested("threshold_fit", threshold_fit);
  check.Above("april_tag_quad_match_cells", april_tag_quad_match_cells, 0.0);
  check.AtLeast("edge_refinement_min_side_px", edge_refinement_min_side_px, 0.0);
  check.AtLeast("edge_refinement_max_side_px", edge_refinement_max_side_px,
                edge_refinement_min_side_px, "edge_refinement_min_side_px");
  check.Nested("edge_refinement_options", edge_refinement_options);
  return check.ok();
}

cv::Ptr<cv::aruco::DetectorParameters> DetectorOptions::ToOpenCv() const {
  cv::Ptr<cv::aruco::DetectorParameters> p = cv::aruco::DetectorParameters::create();
  p->adaptiveThreshWinSizeMin = adaptive_thresh_win_size_min;
  p->adaptiveThreshWinSizeMax = adaptive_thresh_win_size_max;
  p->adaptiveThreshWinSizeStep = adaptive_thresh_win_size_step;
  p->adaptiveThreshConstant = adaptive_thresh_constant;
  p->minMarkerPerimeterRate = min_marker_perimeter_rate;
  p->maxMarkerPerimeterRate = max_marker_perimeter_rate;
  p->polygonalApproxAccuracyRate = polygonal_approx_accuracy_rate;
  p->minCornerDistanceRate = min_corner_distance_rate;
  p->minDistanceToBorder = min_distance_to_border;
  p->minMarkerDistanceRate = min_marker_distance_rate;
  switch (corner_refinement) {
    case CornerRefinement::kNone:
      p->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
      break;
    case CornerRefinement::kSubpix:  // done per marker after detection (RefineSubpix)
      p->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
      break;
    case CornerRefinement::kContour:
      p->cornerRefinementMethod = cv::aruco::CORNER_REFINE_CONTOUR;
      break;
    case CornerRefinement::kAprilTag:
      p->cornerRefinementMethod = cv::aruco::CORNER_REFINE_APRILTAG;
      break;
  }
  p->cornerRefinementWinSize = corner_refinement_win_size;
  p->cornerRefinementMaxIterations = corner_refinement_max_iterations;
  p->cornerRefinementMinAccuracy = corner_refinement_min_accuracy;
  p->perspectiveRemovePixelPerCell = perspective_remove_pixel_per_cell;
  p->perspectiveRemoveIgnoredMarginPerCell = perspective_remove_ignored_margin_per_cell;
  p->maxErroneousBitsInBorderRate = max_erroneous_bits_in_border_rate;
  p->minOtsuStdDev = min_otsu_std_dev;
  p->errorCorrectionRate = error_correction_rate;
  p->detectInvertedMarker = detect_inverted_marker;
  p->markerBorderBits = marker_border_bits;
  p->aprilTagQuadDecimate = static_cast<float>(april_tag_quad_decimate);
  p->aprilTagQuadSigma = static_cast<float>(april_tag_quad_sigma);
  return p;
}

MarkerDetector::MarkerDetector(const DetectorOptions& options) : options_(options) {
  dictionary_ = DictionaryFromName(options.dictionary);  // InputError when unknown
  if (!options.Check()) throw std::invalid_argument("MarkerDetector: invalid DetectorOptions");
  parameters_ = options.ToOpenCv();
}

std::vector<MarkerDetection> RemoveDuplicateDetections(std::vector<MarkerDetection> detections,
                                                       double distance_rate) {
  // Larger perimeter first, so the kept one of each group is the first seen.
  std::stable_sort(detections.begin(), detections.end(),
                   [](const MarkerDetection& a, const MarkerDetection& b) {
                     return a.Perimeter() > b.Perimeter();
                   });
  std::vector<MarkerDetection> kept;
  for (const MarkerDetection& candidate : detections) {
    const bool duplicate = std::any_of(kept.begin(), kept.end(), [&](const MarkerDetection& k) {
      const double side = 0.25 * std::min(k.Perimeter(), candidate.Perimeter());
      return k.id == candidate.id &&
             (k.Center() - candidate.Center()).norm() < distance_rate * side;
    });
    if (!duplicate) kept.push_back(candidate);
  }
  std::sort(kept.begin(), kept.end(), [](const MarkerDetection& a, const MarkerDetection& b) {
    if (a.id != b.id) return a.id < b.id;
    const Eigen::Vector2d ca = a.Center(), cb = b.Center();
    return ca.x() != cb.x() ? ca.x() < cb.x() : ca.y() < cb.y();
  });
  return kept;
}

void MarkerDetector::RefineSubpix(const cv::Mat& gray, std::vector<cv::Point2f>& corners) const {
  const int cells = dictionary_->markerSize + 2 * options_.marker_border_bits;
  const double side = 0.25 * cv::arcLength(corners, true);
  const int half_window = std::clamp(
      static_cast<int>(std::lround(options_.corner_refinement_window_cells * side / cells)), 2,
      options_.corner_refinement_win_size);
  cv::cornerSubPix(gray, corners, cv::Size(half_window, half_window), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::MAX_ITER | cv::TermCriteria::EPS,
                                    options_.corner_refinement_max_iterations,
                                    options_.corner_refinement_min_accuracy));
}

namespace {

cv::Mat GreyImage(const cv::Mat& image) {
  cv::Mat gray = image;
  if (image.channels() == 3) cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  if (image.channels() == 4) cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  if (gray.depth() != CV_8U) throw std::invalid_argument("MarkerDetector: expected 8-bit image");
  return gray;
}

}  // namespace

std::vector<MarkerDetection> MarkerDetector::Detect(const cv::Mat& image) const {
  if (image.empty()) return {};
  const cv::Mat gray = GreyImage(image);
  return RemoveDuplicateDetections(DetectInGray(gray, *parameters_),
                                   options_.dedup_distance_rate);
}

std::vector<MarkerDetection> MarkerDetector::DetectInRegions(
    const cv::Mat& image, const std::vector<cv::Rect>& regions) const {
  if (image.empty()) return {};
  const cv::Mat gray = GreyImage(image);
  const double whole_side = std::max(gray.cols, gray.rows);
  std::vector<MarkerDetection> detections;
  for (const cv::Rect& region : regions) {
    const cv::Rect part = region & cv::Rect(0, 0, gray.cols, gray.rows);
    if (part.empty()) continue;
    // OpenCV's perimeter limits are rates of the searched image's larger side: the part
    // keeps the whole image's limits in pixels.
    const double perimeter_scale = whole_side / std::max(part.width, part.height);
    cv::aruco::DetectorParameters parameters = *parameters_;
    parameters.minMarkerPerimeterRate *= perimeter_scale;
    parameters.maxMarkerPerimeterRate *= perimeter_scale;
    for (MarkerDetection& detection : DetectInGray(gray(part), parameters)) {
      for (Eigen::Vector2d& corner : detection.corners) corner += Eigen::Vector2d(part.x, part.y);
      detections.push_back(detection);
    }
  }
  return RemoveDuplicateDetections(std::move(detections), options_.dedup_distance_rate);
}

std::vector<MarkerDetection> MarkerDetector::DetectInGray(
    const cv::Mat& gray, const cv::aruco::DetectorParameters& parameters) const {
  const double scale = options_.upsample;
  cv::Mat work = gray;
  if (scale > 1.0) cv::resize(gray, work, cv::Size(), scale, scale, cv::INTER_LINEAR);
  std::vector<std::vector<cv::Point2f>> corners, rejected;  // `corners` kept as found
  std::vector<int> ids;
  cv::aruco::detectMarkers(work, dictionary_, corners, ids,
                           cv::makePtr<cv::aruco::DetectorParameters>(parameters), rejected);
  // OpenCV 4.6's AprilTag path returns corners with pixel centres at (0.5, 0.5) (the apriltag
  // library's convention; measured +0.45 px on rendered markers): shift them back.
  const double shift = options_.corner_refinement == CornerRefinement::kAprilTag ? 0.5 : 0.0;
  // cv::resize maps pixel centres as x_work + 0.5 = scale * (x + 0.5).
  const auto to_input = [scale, shift](double x_work) {
    return (x_work - shift + 0.5) / scale - 0.5;
  };
  std::vector<MarkerDetection> detections;
  detections.reserve(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    if (corners[i].size() != 4) continue;
    std::vector<cv::Point2f> refined = corners[i];
    if (options_.corner_refinement == CornerRefinement::kSubpix) RefineSubpix(work, refined);
    MarkerDetection detection;
    detection.id = ids[i];
    for (int k = 0; k < 4; ++k) {
      detection.corners[k] = {to_input(refined[k].x), to_input(refined[k].y)};
    }
    detections.push_back(detection);
  }
  if (options_.rescue_rejected) {
    CandidateDecoderOptions rescue = options_.rescue;
    rescue.marker_border_bits = options_.marker_border_bits;
    // Rejected candidates first; a decoded one that overlaps a marker already found is
    // dropped (OpenCV's own decoding is kept).
    const auto rescue_candidates = [&](const std::vector<std::vector<cv::Point2f>>& candidates) {
      for (const std::vector<cv::Point2f>& candidate : candidates) {
        if (candidate.size() != 4) continue;
        const std::optional<DecodedCandidate> decoded = DecodeCandidate(
            work, {candidate[0], candidate[1], candidate[2], candidate[3]}, *dictionary_, rescue);
        if (!decoded) continue;
        MarkerDetection detection;  // corners refined by the decoder: OpenCV's convention
        detection.id = decoded->id;
        for (int k = 0; k < 4; ++k) {
          detection.corners[k] = {(decoded->corners[k].x + 0.5) / scale - 0.5,
                                  (decoded->corners[k].y + 0.5) / scale - 0.5};
        }
        const bool known =
            std::any_of(detections.begin(), detections.end(), [&](const MarkerDetection& d) {
              return d.id == detection.id &&
                     (d.Center() - detection.Center()).norm() <
                         0.25 * options_.dedup_distance_rate *
                             std::min(d.Perimeter(), detection.Perimeter());
            });
        if (!known) detections.push_back(detection);
      }
    };
    rescue_candidates(rejected);
    // With AprilTag quads, the contour search of OpenCV's default path finds other
    // candidates (some small markers only there): they are decoded last.
    if (options_.corner_refinement == CornerRefinement::kAprilTag &&
        options_.rescue_contour_candidates) {
      std::vector<std::vector<cv::Point2f>> contour_corners, contour_rejected;
      std::vector<int> contour_ids;
      const auto contour_parameters = cv::makePtr<cv::aruco::DetectorParameters>(parameters);
      contour_parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;
      cv::aruco::detectMarkers(work, dictionary_, contour_corners, contour_ids, contour_parameters,
                               contour_rejected);
      rescue_candidates(contour_corners);
      rescue_candidates(contour_rejected);
    }
  }
  const int cells = dictionary_->markerSize + 2 * options_.marker_border_bits;
  std::vector<bool> on_april_tag_quad(detections.size(), false);
  if (options_.april_tag_quad_corners && options_.dictionary.starts_with("DICT_APRILTAG") &&
      options_.marker_border_bits == 1) {
    // The main search's quads are the AprilTag ones at full resolution when it used them;
    // otherwise the quad fit runs around each detection (quiet zone and the threshold's
    // 3 x 3 tiles included).
    const bool reuse = options_.corner_refinement == CornerRefinement::kAprilTag && scale == 1.0;
    const std::vector<Quad> found_quads =
        reuse ? QuadsFromAprilTagDetection(corners, rejected) : std::vector<Quad>{};
    for (size_t i = 0; i < detections.size(); ++i) {
      const double cell = 0.25 * detections[i].Perimeter() / cells;
      const std::vector<Quad> quads =
          reuse ? found_quads
                : FindAprilTagQuadsAround(gray, detections[i].corners, 1.0 * cell + 8.0,
                                          dictionary_, *parameters_);
      on_april_tag_quad[i] = SnapCornersToQuad(quads, cells, options_.april_tag_quad_match_cells,
                                               detections[i].corners);
    }
  }
  // Refits each detection's corners (not those on an AprilTag quad) with `fit`, which takes
  // them as found and returns false to keep them.
  const auto refit_corners = [&](const auto& fit) {
    for (size_t i = 0; i < detections.size(); ++i) {
      if (on_april_tag_quad[i]) continue;
      MarkerDetection& detection = detections[i];
      std::array<cv::Point2f, 4> fitted;
      for (int k = 0; k < 4; ++k) {
        fitted[k] = cv::Point2f(static_cast<float>(detection.corners[k].x()),
                                static_cast<float>(detection.corners[k].y()));
      }
      if (!fit(detection, fitted)) continue;
      for (int k = 0; k < 4; ++k) detection.corners[k] = {fitted[k].x, fitted[k].y};
    }
  };
  // Not with wider borders: in an AprilGrid (2-cell border, small black squares between the
  // tags) the fit took a neighbour's edge (yac_mocap_aprilgrid: corners up to 8.5 px off).
  if (options_.edge_refinement && options_.corner_refinement == CornerRefinement::kSubpix &&
      options_.marker_border_bits == 1 && !options_.threshold_line_fit) {
    refit_corners([&](const MarkerDetection& detection, std::array<cv::Point2f, 4>& fitted) {
      const double side = 0.25 * detection.Perimeter();
      return side >= options_.edge_refinement_min_side_px &&
             side <= options_.edge_refinement_max_side_px &&
             RefineQuadEdges(gray, cells, options_.edge_refinement_options, fitted);
    });
  }
  if (options_.threshold_line_fit) {
    refit_corners([&](const MarkerDetection&, std::array<cv::Point2f, 4>& fitted) {
      return FitQuadToThreshold(gray, cells, options_.threshold_fit, fitted);
    });
  }
  return detections;
}

}  // namespace arucoslam
