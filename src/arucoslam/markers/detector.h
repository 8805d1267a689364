// MarkerDetector: finds ArUco (and AprilTag-family) markers of one dictionary in a grey
// image with OpenCV's aruco module; returns each marker's id and its four corner pixels.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "arucoslam/markers/april_tag_quads.h"
#include "arucoslam/markers/candidate_decoder.h"
#include "arucoslam/markers/edge_refiner.h"
#include "arucoslam/markers/threshold_line_fit.h"

namespace arucoslam {

// One detected marker: corners in OpenCV order (top-left, top-right, bottom-right,
// bottom-left of the marker as printed), pixels in the (distorted) input image, with pixel
// centres at integer coordinates whatever the refinement.
struct MarkerDetection {
  int id = -1;
  std::array<Eigen::Vector2d, 4> corners;

  Eigen::Vector2d Center() const;
  double Perimeter() const;  // pixels
};

enum class CornerRefinement { kNone, kSubpix, kContour, kAprilTag };

// The OpenCV DetectorParameters that matter, with OpenCV's defaults unless said otherwise.
struct DetectorOptions {
  std::string dictionary = "DICT_4X4_50";  // any name of DictionaryNames()

  int adaptive_thresh_win_size_min = 3;          // pixels, odd window sides tried from min to max
  int adaptive_thresh_win_size_max = 23;         // pixels
  int adaptive_thresh_win_size_step = 10;        // pixels
  double adaptive_thresh_constant = 7.0;         // grey levels subtracted from the local mean
  double min_marker_perimeter_rate = 0.03;       // of the larger image side
  double max_marker_perimeter_rate = 4.0;        // of the larger image side
  double polygonal_approx_accuracy_rate = 0.03;  // of the candidate's perimeter
  double min_corner_distance_rate = 0.05;        // of the candidate's perimeter
  int min_distance_to_border = 3;                // pixels
  // OpenCV's default is 0.05. It is 0 here: OpenCV 4.6 then keeps the outer contour of a
  // narrow white margin over the marker itself (DESIGN.md, known pitfalls); duplicates of
  // one marker are removed afterwards (see dedup_distance_rate).
  double min_marker_distance_rate = 0.0;
  CornerRefinement corner_refinement = CornerRefinement::kSubpix;  // OpenCV default: kNone
  // kSubpix: cv::cornerSubPix on each corner with a half window of
  // corner_refinement_window_cells x the marker's cell size, clamped to
  // [2, corner_refinement_win_size] pixels. A fixed window wider than a cell (OpenCV 4.6's
  // behaviour) lets small markers' corners jump to inner cell corners (measured: up to 6 px).
  int corner_refinement_win_size = 5;           // pixels (largest half window)
  double corner_refinement_window_cells = 0.6;  // fraction of a cell, > 0
  int corner_refinement_max_iterations = 30;
  double corner_refinement_min_accuracy = 0.1;               // pixels
  int perspective_remove_pixel_per_cell = 4;                 // pixels per cell when decoding
  double perspective_remove_ignored_margin_per_cell = 0.13;  // fraction of a cell
  double max_erroneous_bits_in_border_rate = 0.35;
  double min_otsu_std_dev = 5.0;       // grey levels
  double error_correction_rate = 0.6;  // fraction of the dictionary's correction capacity
  bool detect_inverted_marker = false;
  int marker_border_bits = 1;  // black border width in cells (2 for Kalibr-style AprilGrids)
  // kAprilTag refinement only (it then finds quads with the AprilTag algorithm): image
  // decimation before quad detection (0 or 1: full resolution, OpenCV's default) and blur.
  double april_tag_quad_decimate = 0.0;  // 0, or >= 1
  double april_tag_quad_sigma = 0.0;     // Gaussian sigma, pixels, >= 0
  // Two detections of the same id whose centres are closer than this fraction of the
  // smaller one's side are one marker; the one with the larger perimeter is kept.
  double dedup_distance_rate = 0.5;
  // Scale factor applied to the grey image (cv::resize, INTER_LINEAR) before detection;
  // corners are mapped back to the input image. 1: none. Markers under about 25 px wide
  // (3 px per cell or less) are found far more often at 2 or 3, but the cost grows: per
  // 640x480 frame, measured 6-7 ms at 1, 12-13 ms at 2, 22-23 ms at 3 (CPU time of the
  // calling thread, bench/marker_bench.cc BM_DetectSmallMarkerOptions), so SLAM frames keep 1.
  double upsample = 1.0;  // >= 1, <= 8
  // Candidates that OpenCV rejects (bits unreadable on its decoding grid, as on
  // small, tilted or blurred markers) are decoded again with sub-pixel corners and bilinear
  // cell sampling (candidate_decoder.h), with the stricter tolerances of `rescue`. Costs
  // 0-15% more per 640x480 frame (same benchmark: 6.2 against 6.2 ms, 7.9 against 6.8 ms),
  // growing with the number of rejected candidates (textured scenes have more).
  bool rescue_rejected = false;
  CandidateDecoderOptions rescue;  // its marker_border_bits is taken from above
  // kAprilTag refinement with rescue_rejected: the candidates of OpenCV's contour search
  // are decoded as well (small markers that the AprilTag quads miss). Costs about 10% more
  // on the AprilTag photos (bench/marker_bench.cc BM_DetectAprilTagPhoto).
  bool rescue_contour_candidates = true;
  // Every detection's corners refitted on the input image to the crossings of a local
  // threshold (threshold_line_fit.h), whatever found them; kept as found where the fit
  // fails. On the apriltag_detect_unit photos (AprilTag options above) the mean corner
  // distance to the apriltag library's corners drops from 0.38 to 0.29 px; on rendered small
  // tilted markers the mean error to the truth from 0.12 to 0.09 px (AprilTag options) and
  // from 0.35 to 0.08 px (the defaults; detector_test.cc,
  // ThresholdLineFitCornersOnRenderedMarkers). Off by default: on large sharp markers it
  // places corners about 0.3 px further out than cornerSubPix (fiducials_aruco_unit:
  // 0.33 px mean from the peer's corners, against 0.02 px). Costs about 0.2 ms per marker
  // (CPU time, bench/marker_bench.cc BM_DetectThresholdLineFit: 8.9 against 8.2 ms per
  // 640x480 frame with 4 markers; BM_DetectAprilTagPhoto: 222 against 212 ms for 30 tags).
  bool threshold_line_fit = false;
  ThresholdLineFitOptions threshold_fit;
  // kSubpix, 1-cell border: markers edge_refinement_min_side_px to edge_refinement_max_side_px
  // on a side (mean, input pixels) get their corners refitted from their four edges
  // (edge_refiner.h); kept as cornerSubPix left them where the fit fails. cornerSubPix, with its
  // window of 0.6 cells, leaves a small blurred marker's corners inside the true ones: on the
  // simulator's factory route, 20-40 px markers are 0.14-0.22 px too small at each corner
  // (0.17-0.25 px RMS), the edge fit 0.00-0.02 px (0.05-0.08 px RMS), and the camera position from
  // one 20-40 px marker improves from 0.20 to 0.12 m mean (detector_test.cc,
  // EdgeRefinementRemovesTheInwardBiasOfSmallMarkers, for rendered markers). Under 20 px the
  // border is under 3.3 px wide and the fit can take the edge of a board around the marker
  // (15-20 px markers on the factory's wall boards: +0.14 px outward, 0.30 px RMS). Over 60 px
  // cornerSubPix's bias is under 0.1 px and a whole side is no longer straight in a distorted
  // image: on the fiducials_aruco_unit photos (sides of 100-200 px, raw) the edge fit moves
  // corners up to 0.7 px from the peer's cornerSubPix ones.
  bool edge_refinement = true;
  double edge_refinement_min_side_px = 20.0;
  double edge_refinement_max_side_px = 60.0;
  EdgeRefineOptions edge_refinement_options = {.derivative_half_width_px = 0.5};
  // AprilTag dictionaries (DICT_APRILTAG_*) with the standard 1-cell border only: each
  // detection, whatever found it, takes the corners of the AprilTag quad fit on the input
  // image (april_tag_quads.h; where the apriltag library places them) when one of its quads
  // has every corner within april_tag_quad_match_cells cells of the detection's; the
  // threshold line fit is then skipped for it. apriltag_detect_unit: 47 of 47 tags within
  // 1 px of the library's corners (mean 0.005 px). Rendered tag36h11 markers (default
  // options, cells of 2-14 px, blur, JPEG): mean error to the truth 0.10-0.23 px, against
  // 0.21-0.32 px with cornerSubPix alone; but 0.17 against 0.12 px from AprilTag quads at 2x
  // (detector_test.cc). Not used with 2-cell borders (Kalibr AprilGrids):
  // on yac_mocap_aprilgrid the quads put corners 0.37 px (median) from yac's, against 0.13 px,
  // and raise the median reprojection error from 0.30 to 0.47 px (0.29 to 0.46 px on the
  // undistorted images: not lens distortion). Unless the search above used AprilTag quads at
  // full resolution, the quad fit runs again around each detection (its cost grows with the
  // area: CPU time, bench/marker_bench.cc BM_DetectAprilTagDictionary: 13.3 against 6.4 ms
  // per 640x480 frame with 4 tags of 35-65 px; BM_DetectAprilTagPhoto: 217 against 207 ms
  // for 30 tags of 10-45 px).
  bool april_tag_quad_corners = true;
  double april_tag_quad_match_cells = 1.0;  // > 0

  bool Check(std::string* why = nullptr) const;
  cv::Ptr<cv::aruco::DetectorParameters> ToOpenCv() const;
};

class MarkerDetector {
 public:
  // Throws InputError for an unknown dictionary, std::invalid_argument for bad options.
  explicit MarkerDetector(const DetectorOptions& options = {});

  // `image`: 8-bit grey or BGR (converted to grey). Detections are sorted by id, then by
  // position; each id appears once per physical marker.
  std::vector<MarkerDetection> Detect(const cv::Mat& image) const;
  // Detect on the parts `regions` of the image only (clipped to it): each part is searched
  // as a whole image would be, with the whole image's perimeter limits in pixels. A marker
  // lying in one region at least MarkerRegionMargin(options) pixels from its sides
  // (detector_regions.h) is found as Detect finds it (same id, same corners); overlapping
  // regions should be merged beforehand (SearchRegions does). Cheaper than Detect in
  // proportion to the area searched.
  std::vector<MarkerDetection> DetectInRegions(const cv::Mat& image,
                                               const std::vector<cv::Rect>& regions) const;

  const DetectorOptions& options() const { return options_; }

 private:
  void RefineSubpix(const cv::Mat& gray, std::vector<cv::Point2f>& corners) const;
  // Detections in `gray` (the whole image or a part of it, with `parameters` whose perimeter
  // rates are scaled for that part), duplicates not yet removed.
  std::vector<MarkerDetection> DetectInGray(const cv::Mat& gray,
                                            const cv::aruco::DetectorParameters& parameters) const;

  DetectorOptions options_;
  cv::Ptr<cv::aruco::Dictionary> dictionary_;
  cv::Ptr<cv::aruco::DetectorParameters> parameters_;
};

// Removes duplicates (same id, centres closer than `distance_rate` x side), keeping the
// detection with the larger perimeter. Exposed for tests.
std::vector<MarkerDetection> RemoveDuplicateDetections(std::vector<MarkerDetection> detections,
                                                       double distance_rate);

}  // namespace arucoslam
