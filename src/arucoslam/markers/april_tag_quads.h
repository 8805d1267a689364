// Quadrilaterals found by the AprilTag quad fit (OpenCV's port of the apriltag library's
// segmentation and line fits), and detected corners moved onto the matching one, so that
// AprilTag-family corners sit where the reference library places them.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <vector>

namespace arucoslam {

using Quad = std::array<cv::Point2f, 4>;

// Every quad of the AprilTag quad fit on `gray` (8-bit), decoded by OpenCV or not, with pixel
// centres at integer coordinates. `parameters`: the detection's, its refinement method is
// replaced by CORNER_REFINE_APRILTAG.
std::vector<Quad> FindAprilTagQuads(const cv::Mat& gray,
                                    const cv::Ptr<cv::aruco::Dictionary>& dictionary,
                                    const cv::aruco::DetectorParameters& parameters);

// The same search on a crop of `gray` around `corners` only (their bounding box grown by
// margin_px on each side), cheaper than the whole image when markers are few. The crop
// starts on a multiple of 4 px, as the quad fit's threshold tiles do, so the quads near
// the marker are those of the whole image.
std::vector<Quad> FindAprilTagQuadsAround(const cv::Mat& gray,
                                          const std::array<Eigen::Vector2d, 4>& corners,
                                          double margin_px,
                                          const cv::Ptr<cv::aruco::Dictionary>& dictionary,
                                          const cv::aruco::DetectorParameters& parameters);

// The quads of one cv::aruco::detectMarkers call made with CORNER_REFINE_APRILTAG (accepted
// and rejected), moved from the apriltag library's pixel centres (0.5) to OpenCV's (0).
std::vector<Quad> QuadsFromAprilTagDetection(const std::vector<std::vector<cv::Point2f>>& accepted,
                                             const std::vector<std::vector<cv::Point2f>>& rejected);

// Replaces `corners` (any winding, order kept) by the corners of the nearest quad whose
// every corner is within max_distance_cells cells of the detected one (`cells` across,
// border included; a corner's cell is its shorter side / cells). False (corners unchanged)
// when no quad is that close.
bool SnapCornersToQuad(const std::vector<Quad>& quads, int cells, double max_distance_cells,
                       std::array<Eigen::Vector2d, 4>& corners);

}  // namespace arucoslam
