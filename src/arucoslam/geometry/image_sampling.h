// Sub-pixel reading of a grey image: the bilinear interpolation of the four pixels around a
// point, for code that samples images along lines or grids (marker decoding, edge fitting).
#pragma once

#include <algorithm>
#include <opencv2/core.hpp>

namespace arucoslam {

// Grey value of the 8-bit single-channel `gray` (at least 2 x 2 pixels) at pixel coordinates
// (x, y), pixel centres at integers, interpolated bilinearly. A point off the image is
// clamped onto it (its last column and row at 1/1000 px inside, so the four pixels exist).
inline double BilinearGrey(const cv::Mat& gray, double x, double y) {
  x = std::clamp(x, 0.0, gray.cols - 1.001);
  y = std::clamp(y, 0.0, gray.rows - 1.001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double ax = x - x0, ay = y - y0;
  const uchar* row0 = gray.ptr<uchar>(y0);
  const uchar* row1 = gray.ptr<uchar>(y0 + 1);
  return (1 - ay) * ((1 - ax) * row0[x0] + ax * row0[x0 + 1]) +
         ay * ((1 - ax) * row1[x0] + ax * row1[x0 + 1]);
}

}  // namespace arucoslam
