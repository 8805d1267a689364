#include "arucoslam/io/rosbag/camera_info.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "arucoslam/io/calibration.h"

namespace arucoslam {

std::string CameraInfoYaml(const sensor_msgs::CameraInfo& info) {
  // Drivers of distortion-free cameras publish plumb_bob with an empty D.
  const std::string model = info.D.empty() ? "none" : info.distortion_model;
  std::string text = fmt::format(
      "image_width: {}\nimage_height: {}\ndistortion_model: {}\nK: [{}]\n", info.width,
      info.height, model.empty() ? "''" : model, fmt::join(info.K, ", "));
  if (!info.D.empty()) text += fmt::format("D: [{}]\n", fmt::join(info.D, ", "));
  return text;
}

CameraModel CameraFromInfo(const sensor_msgs::CameraInfo& info, const std::string& source) {
  return ParseCameraCalibration(CameraInfoYaml(info), source).camera;
}

sensor_msgs::CameraInfo CameraInfoFromModel(const CameraModel& camera) {
  sensor_msgs::CameraInfo info;
  info.width = static_cast<std::uint32_t>(camera.width);
  info.height = static_cast<std::uint32_t>(camera.height);
  info.K = {camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {camera.fx, 0.0, camera.cx, 0.0, 0.0, camera.fy, camera.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  switch (camera.model) {
    case DistortionModel::kNone:
      info.distortion_model = "plumb_bob";
      info.D.assign(5, 0.0);
      break;
    case DistortionModel::kRadTan:
      info.distortion_model = "plumb_bob";
      info.D.assign(camera.distortion.begin(), camera.distortion.begin() + 5);
      break;
    case DistortionModel::kEquidistant:
      info.distortion_model = "equidistant";
      info.D.assign(camera.distortion.begin(), camera.distortion.begin() + 4);
      break;
    case DistortionModel::kRational:
      info.distortion_model = "rational_polynomial";
      info.D.assign(camera.distortion.begin(), camera.distortion.begin() + 8);
      break;
    case DistortionModel::kThinPrism:
    case DistortionModel::kTilted:
      // camera_info has no name for these: the full OpenCV vector under its own label.
      info.distortion_model = DistortionModelName(camera.model);
      info.D.assign(camera.distortion.begin(), camera.distortion.end());
      break;
  }
  return info;
}

}  // namespace arucoslam
