#include "arucoslam/markers/candidate_decoder.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "arucoslam/geometry/image_sampling.h"
#include "arucoslam/markers/edge_refiner.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

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

// Mean grey level of each cell of the quadrilateral `corners` (cells x cells) and of `ring`
// more cells around it, row-major over (cells + 2 ring)^2; empty when a sample falls behind
// the homography.
std::vector<double> SampleCells(const cv::Mat& gray, const std::array<cv::Point2f, 4>& corners,
                                int cells, int ring, const CandidateDecoderOptions& options) {
  const std::vector<cv::Point2f> canonical = {
      {0.f, 0.f}, {float(cells), 0.f}, {float(cells), float(cells)}, {0.f, float(cells)}};
  const cv::Matx33d h = cv::getPerspectiveTransform(
      canonical, std::vector<cv::Point2f>(corners.begin(), corners.end()));
  const int s = options.samples_per_cell;
  const double span = 1.0 - 2.0 * options.ignored_margin_per_cell;
  const int n = cells + 2 * ring;
  std::vector<double> values(n * n);
  for (int row = -ring; row < cells + ring; ++row) {
    for (int col = -ring; col < cells + ring; ++col) {
      double sum = 0.0;
      for (int i = 0; i < s; ++i) {
        for (int j = 0; j < s; ++j) {
          const double u = col + options.ignored_margin_per_cell + span * (j + 0.5) / s;
          const double v = row + options.ignored_margin_per_cell + span * (i + 0.5) / s;
          const cv::Vec3d p = h * cv::Vec3d(u, v, 1.0);
          if (p[2] <= 0.0) return {};
          sum += BilinearGrey(gray, p[0] / p[2], p[1] / p[2]);
        }
      }
      values[(row + ring) * n + col + ring] = sum / (s * s);
    }
  }
  return values;
}

}  // namespace

bool CandidateDecoderOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("marker_border_bits", marker_border_bits, 1);
  check.AtLeast("samples_per_cell", samples_per_cell, 1);
  check.InRange("ignored_margin_per_cell", ignored_margin_per_cell, 0.0, 0.5,
                Interval::kClosedOpen);
  check.AtLeast("min_contrast", min_contrast, 0.0);
  check.AtLeast("max_erroneous_border_bits", max_erroneous_border_bits, 0);
  check.InRange("error_correction_rate", error_correction_rate, 0.0, 1.0, Interval::kClosed);
  check.Above("refine_window_cells", refine_window_cells, 0.0);
  check.Above("max_refine_shift_cells", max_refine_shift_cells, 0.0);
  check.AtLeast("sharpening", sharpening, 0.0);
  check.Nested("edges", edges);
  return check.ok();
}

namespace {

// Identifies the bits (cells x cells, true: white) after checking the black border.
bool Identify(const std::vector<bool>& white, int cells, const cv::aruco::Dictionary& dictionary,
              const CandidateDecoderOptions& options, int& id, int& rotation) {
  const int b = options.marker_border_bits, inner = dictionary.markerSize;
  int border_errors = 0;
  cv::Mat bits(inner, inner, CV_8UC1);
  for (int row = 0; row < cells; ++row) {
    for (int col = 0; col < cells; ++col) {
      const bool is_white = white[row * cells + col];
      if (row < b || col < b || row >= cells - b || col >= cells - b) {
        border_errors += is_white;
      } else {
        bits.at<uchar>(row - b, col - b) = is_white ? 1 : 0;
      }
    }
  }
  if (border_errors > options.max_erroneous_border_bits) return false;
  return dictionary.identify(bits, id, rotation, options.error_correction_rate);
}

// Global decision: Otsu's threshold over the cell means (`values`: cells x cells).
bool OtsuDecode(const std::vector<double>& values, int cells,
                const cv::aruco::Dictionary& dictionary, const CandidateDecoderOptions& options,
                int& id, int& rotation) {
  const auto [lowest, highest] = std::minmax_element(values.begin(), values.end());
  if (*highest - *lowest < options.min_contrast) return false;
  const double threshold = OtsuThreshold(values);
  std::vector<bool> white(values.size());
  for (size_t i = 0; i < values.size(); ++i) white[i] = values[i] > threshold;
  return Identify(white, cells, dictionary, options, id, rotation);
}

// Least-squares plane v = a + b col + c row through the cells listed in `at`.
cv::Vec3d FitPlane(const std::vector<double>& values, int n, const std::vector<int>& at) {
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0, 0, 0);
  for (int i : at) {
    const cv::Vec3d x(1.0, i % n, i / n);
    normal += x * x.t();
    rhs += values[i] * x;
  }
  cv::Vec3d plane;
  cv::solve(normal, rhs, plane, cv::DECOMP_SVD);
  return plane;
}

// Local decision (for small, blurred or unevenly lit markers): the black level is a plane
// fitted to the border cells and the white level one fitted to the quiet-zone ring around
// the marker; each cell is compared with their mean there after a sharpening that undoes
// part of the blur between neighbouring cells. `values`: (cells + 2)^2 with the ring.
// False when the ring is not white enough to serve.
bool RingDecode(const std::vector<double>& values, int cells,
                const cv::aruco::Dictionary& dictionary, const CandidateDecoderOptions& options,
                int& id, int& rotation) {
  const int n = cells + 2, b = options.marker_border_bits;
  std::vector<int> ring, border;
  for (int row = 0; row < n; ++row) {
    for (int col = 0; col < n; ++col) {
      const int r = std::min({row, col, n - 1 - row, n - 1 - col});  // 0: ring
      if (r == 0) ring.push_back(row * n + col);
      if (r >= 1 && r <= b) border.push_back(row * n + col);
    }
  }
  const cv::Vec3d white_plane = FitPlane(values, n, ring);
  const cv::Vec3d black_plane = FitPlane(values, n, border);
  const auto level = [](const cv::Vec3d& plane, double col, double row) {
    return plane[0] + plane[1] * col + plane[2] * row;
  };
  // The ring must be brighter than the border all over the marker.
  for (const double corner_col : {0.0, double(n - 1)}) {
    for (const double corner_row : {0.0, double(n - 1)}) {
      if (level(white_plane, corner_col, corner_row) - level(black_plane, corner_col, corner_row) <
          options.min_contrast) {
        return false;
      }
    }
  }
  std::vector<double> offset(n * n);
  for (int i = 0; i < n * n; ++i) {
    const double col = i % n, row = i / n;
    offset[i] = values[i] - 0.5 * (level(white_plane, col, row) + level(black_plane, col, row));
  }
  std::vector<bool> white(cells * cells);
  for (int row = 1; row <= cells; ++row) {
    for (int col = 1; col <= cells; ++col) {
      const int i = row * n + col;
      const double laplacian =
          4.0 * offset[i] - offset[i - 1] - offset[i + 1] - offset[i - n] - offset[i + n];
      white[(row - 1) * cells + col - 1] = offset[i] + options.sharpening * laplacian > 0.0;
    }
  }
  return Identify(white, cells, dictionary, options, id, rotation);
}

// The marker's own cells (cells x cells) out of values sampled with the ring.
std::vector<double> InnerCells(const std::vector<double>& values, int cells) {
  const int n = cells + 2;
  std::vector<double> inner;
  inner.reserve(cells * cells);
  for (int row = 1; row <= cells; ++row) {
    for (int col = 1; col <= cells; ++col) inner.push_back(values[row * n + col]);
  }
  return inner;
}


// Reads and identifies the quadrilateral `corners` (refined, clockwise).
std::optional<DecodedCandidate> DecodeRefined(const cv::Mat& gray,
                                              std::array<cv::Point2f, 4> corners, int cells,
                                              const cv::aruco::Dictionary& dictionary,
                                              const CandidateDecoderOptions& options) {
  const std::vector<double> values = SampleCells(gray, corners, cells, 1, options);
  if (values.empty()) return std::nullopt;
  DecodedCandidate decoded;
  int rotation = 0;
  if (!(options.ring_threshold &&
        RingDecode(values, cells, dictionary, options, decoded.id, rotation)) &&
      !OtsuDecode(InnerCells(values, cells), cells, dictionary, options, decoded.id, rotation)) {
    return std::nullopt;
  }
  // As OpenCV does: the identified rotation moves the marker's first corner.
  std::rotate(corners.begin(), corners.begin() + (4 - rotation) % 4, corners.end());
  decoded.corners = corners;
  return decoded;
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
  // Edge-fitted corners first; when they fail or do not decode, cornerSubPix ones.
  std::array<cv::Point2f, 4> fitted = corners;
  if (options.edge_refinement && RefineQuadEdges(gray, cells, options.edges, fitted)) {
    if (std::optional<DecodedCandidate> decoded =
            DecodeRefined(gray, fitted, cells, dictionary, options)) {
      return decoded;
    }
  }
  if (!RefineCorners(gray, cells, options.refine_window_cells, options.max_refine_shift_cells,
                     corners)) {
    return std::nullopt;
  }
  return DecodeRefined(gray, corners, cells, dictionary, options);
}

}  // namespace arucoslam
