#include "arucoslam/markers/candidate_decoder.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace arucoslam {
namespace {

// Bilinear grey value at (x, y); the caller keeps (x, y) inside the image.
double Bilinear(const cv::Mat& gray, double x, double y) {
  x = std::clamp(x, 0.0, gray.cols - 1.001);
  y = std::clamp(y, 0.0, gray.rows - 1.001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double ax = x - x0, ay = y - y0;
  const uchar* row0 = gray.ptr<uchar>(y0);
  const uchar* row1 = gray.ptr<uchar>(y0 + 1);
  return (1 - ay) * ((1 - ax) * row0[x0] + ax * row0[x0 + 1]) +
         ay * ((1 - ax) * row1[x0] + ax * row1[x0 + 1]);
}

// Otsu's threshold over a few values: the split maximising the between-class variance.
double OtsuThreshold(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const int n = static_cast<int>(values.size());
  double total = 0.0;
  for (double v : values) total += v;
  double best_score = -1.0, threshold = values.front(), below = 0.0;
  for (int k = 1; k < n; ++k) {
    below += values[k - 1];
    const double mean_low = below / k, mean_high = (total - below) / (n - k);
    const double score = double(k) * (n - k) * (mean_high - mean_low) * (mean_high - mean_low);
    if (score > best_score) {
      best_score = score;
      threshold = 0.5 * (values[k - 1] + values[k]);
    }
  }
  return threshold;
}

// False when a corner moves more than max_shift_cells: its place is then unknown.
bool RefineCorners(const cv::Mat& gray, int cells, double window_cells, double max_shift_cells,
                   std::array<cv::Point2f, 4>& corners) {
  const double side =
      0.25 * cv::arcLength(std::vector<cv::Point2f>(corners.begin(), corners.end()), true);
  const double cell = side / cells;
  const int half_window = std::max(2, static_cast<int>(std::lround(window_cells * cell)));
  std::vector<cv::Point2f> refined(corners.begin(), corners.end());
  cv::cornerSubPix(gray, refined, cv::Size(half_window, half_window), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::MAX_ITER | cv::TermCriteria::EPS, 30, 0.05));
  for (int k = 0; k < 4; ++k) {
    if (cv::norm(refined[k] - corners[k]) > max_shift_cells * cell) return false;
    corners[k] = refined[k];
  }
  return true;
}

// Mean grey level of each cell (row-major, cells x cells) of the quadrilateral `corners`;
// empty when a sample falls behind the homography.
std::vector<double> SampleCells(const cv::Mat& gray, const std::array<cv::Point2f, 4>& corners,
                                int cells, const CandidateDecoderOptions& options) {
  const std::vector<cv::Point2f> canonical = {
      {0.f, 0.f}, {float(cells), 0.f}, {float(cells), float(cells)}, {0.f, float(cells)}};
  const cv::Matx33d h = cv::getPerspectiveTransform(
      canonical, std::vector<cv::Point2f>(corners.begin(), corners.end()));
  const int s = options.samples_per_cell;
  const double span = 1.0 - 2.0 * options.ignored_margin_per_cell;
  std::vector<double> values(cells * cells);
  for (int row = 0; row < cells; ++row) {
    for (int col = 0; col < cells; ++col) {
      double sum = 0.0;
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) {
          const double u = col + options.ignored_margin_per_cell + span * (j + 0.5) / s;
          const double v = row + options.ignored_margin_per_cell + span * (i + 0.5) / s;
          const cv::Vec3d p = h * cv::Vec3d(u, v, 1.0);
          if (p[2] <= 0.0) return {};
          sum += Bilinear(gray, p[0] / p[2], p[1] / p[2]);
        }
      }
      values[row * cells + col] = sum / (s * s);
    }
  }
  return values;
}

}  // namespace

bool CandidateDecoderOptions::Check() const {
  return marker_border_bits >= 1 && samples_per_cell >= 1 && ignored_margin_per_cell >= 0.0 &&
         ignored_margin_per_cell < 0.5 && min_contrast >= 0.0 && max_erroneous_border_bits >= 0 &&
         error_correction_rate >= 0.0 && error_correction_rate <= 1.0 &&
         refine_window_cells > 0.0 && max_refine_shift_cells > 0.0;
}

namespace {

// Threshold decision: Otsu over the cell means, black border checked, then identified by
// the dictionary with error correction. Sets id and rotation (OpenCV's meaning).
bool HardDecode(const std::vector<double>& values, int cells,
                const cv::aruco::Dictionary& dictionary, const CandidateDecoderOptions& options,
                int& id, int& rotation) {
  const auto [lowest, highest] = std::minmax_element(values.begin(), values.end());
  if (*highest - *lowest < options.min_contrast) return false;
  const double threshold = OtsuThreshold(values);
  const int b = options.marker_border_bits, inner = dictionary.markerSize;
  int border_errors = 0;
  cv::Mat bits(inner, inner, CV_8UC1);
  for (int row = 0; row < cells; ++row) {
    for (int col = 0; col < cells; ++col) {
      const bool white = values[row * cells + col] > threshold;
      if (row < b || col < b || row >= cells - b || col >= cells - b) {
        border_errors += white;
      } else {
        bits.at<uchar>(row - b, col - b) = white ? 1 : 0;
      }
    }
  }
  if (border_errors > options.max_erroneous_border_bits) return false;
  return dictionary.identify(bits, id, rotation, options.error_correction_rate);
}

}  // namespace

std::optional<DecodedCandidate> DecodeCandidate(const cv::Mat& gray,
                                                std::array<cv::Point2f, 4> corners,
                                                const cv::aruco::Dictionary& dictionary,
                                                const CandidateDecoderOptions& options) {
  // Clockwise on screen (y down), as OpenCV orders its candidates.
  const cv::Point2f d1 = corners[1] - corners[0], d2 = corners[2] - corners[0];
  if (d1.x * d2.y - d1.y * d2.x < 0) std::swap(corners[1], corners[3]);
  const int cells = dictionary.markerSize + 2 * options.marker_border_bits;
  if (!RefineCorners(gray, cells, options.refine_window_cells, options.max_refine_shift_cells,
                     corners)) {
    return std::nullopt;
  }
  const std::vector<double> values = SampleCells(gray, corners, cells, options);
  if (values.empty()) return std::nullopt;
  DecodedCandidate decoded;
  int rotation = 0;
  if (!HardDecode(values, cells, dictionary, options, decoded.id, rotation)) return std::nullopt;
  // As OpenCV does: the identified rotation moves the marker's first corner.
  std::rotate(corners.begin(), corners.begin() + (4 - rotation) % 4, corners.end());
  decoded.corners = corners;
  return decoded;
}

}  // namespace arucoslam
