#include "arucoslam/markers/preprocess.h"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool PreprocessOptions::Check(std::string* why) const {
  OptionCheck check(why);
  if (clahe) {
    check.Above("clahe_clip_limit", clahe_clip_limit, 0.0);
    check.AtLeast("clahe_tile_grid", clahe_tile_grid, 1);
  }
  switch (denoise) {
    case DenoiseMethod::kNone:
      return check.ok();
    case DenoiseMethod::kGaussian:
      check.Rule(gaussian_sigma_px > 0.0 && std::isfinite(gaussian_sigma_px), "gaussian_sigma_px",
                 gaussian_sigma_px, "finite and > 0");
      return check.ok();
    case DenoiseMethod::kBilateral:
      check.AtLeast("bilateral_diameter_px", bilateral_diameter_px, 3);
      check.Above("bilateral_sigma_color", bilateral_sigma_color, 0.0);
      check.Above("bilateral_sigma_space_px", bilateral_sigma_space_px, 0.0);
      return check.ok();
  }
  return check.Require(false, "denoise", "a known method").ok();
}

namespace {

cv::Mat ToGray8(const cv::Mat& image) {
  cv::Mat gray;
  if (image.channels() == 3) {
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  } else if (image.channels() == 1) {
    gray = image.clone();
  } else {
    throw std::invalid_argument("Preprocess: unsupported number of channels");
  }
  if (gray.depth() == CV_16U) {
    gray.convertTo(gray, CV_8U, 1.0 / 257.0);
  } else if (gray.depth() == CV_32F || gray.depth() == CV_64F) {
    gray.convertTo(gray, CV_8U, 255.0);  // float images are taken as 0..1
  } else if (gray.depth() != CV_8U) {
    throw std::invalid_argument("Preprocess: unsupported pixel depth");
  }
  return gray;
}

}  // namespace

cv::Mat Preprocess(const cv::Mat& image, const PreprocessOptions& options) {
  if (image.empty()) throw std::invalid_argument("Preprocess: empty image");
  if (!options.Check()) throw std::invalid_argument("Preprocess: invalid options");
  cv::Mat gray = ToGray8(image);
  if (options.clahe) {
    cv::Ptr<cv::CLAHE> clahe = cv::createCLAHE(
        options.clahe_clip_limit, cv::Size(options.clahe_tile_grid, options.clahe_tile_grid));
    cv::Mat equalised;
    clahe->apply(gray, equalised);
    gray = equalised;
  }
  if (options.denoise == DenoiseMethod::kGaussian) {
    cv::GaussianBlur(gray, gray, cv::Size(0, 0), options.gaussian_sigma_px);
  } else if (options.denoise == DenoiseMethod::kBilateral) {
    cv::Mat filtered;
    cv::bilateralFilter(gray, filtered, options.bilateral_diameter_px,
                        options.bilateral_sigma_color, options.bilateral_sigma_space_px);
    gray = filtered;
  }
  return gray;
}

}  // namespace arucoslam
