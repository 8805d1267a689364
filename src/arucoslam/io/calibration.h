// Camera calibration files: reads a CameraModel from a EuRoC sensor.yaml, an ORB-SLAM3-style
// settings YAML, a ROS camera_info YAML, an OpenCV FileStorage YAML or XML or a Kalibr
// camchain.yaml (format found from the content); writes sensor.yaml.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

enum class CalibrationFormat {
  kEuRoC,          // EuRoC / Kalibr sensor.yaml: intrinsics, resolution, distortion_model
  kOrbSlam3,       // ORB-SLAM3 settings: Camera.fx ... or File.version "1.0" + Camera1.fx ...
  kRosCameraInfo,  // ROS camera_info: image_width, distortion_model, camera_matrix.data (or K)
  kOpenCv,         // OpenCV FileStorage YAML/XML: image_width, camera_matrix, no distortion_model
  kKalibr,         // Kalibr camchain.yaml: cam0 {camera_model, intrinsics, distortion_coeffs}
};

std::string CalibrationFormatName(CalibrationFormat format);

// What a calibration file says about one camera.
struct CameraCalibration {
  CameraModel camera;
  // The camera's mounting where the file gives it (EuRoC T_BS, ORB-SLAM3 Tbc or
  // IMU.T_b_c1, the inverse of Kalibr's T_cam_imu), else identity.
  Rigid3 body_from_cam;
  CalibrationFormat format = CalibrationFormat::kEuRoC;
};

// Reads a calibration file of any of the five formats. Distortion coefficients that are all
// zero give DistortionModel::kNone. Throws InputError naming the file and the first bad field
// ("intrinsics: expected 4 numbers, found 3"): missing file, not YAML, unknown format,
// missing field, wrong count, non-number, unknown model, non-positive size or focal length.
CameraCalibration ReadCameraCalibration(const std::filesystem::path& path);
CameraModel ReadCameraModel(const std::filesystem::path& path);

// The same from text already in memory; `source` names it in errors. A leading OpenCV
// "%YAML:1.0" directive line is accepted.
CameraCalibration ParseCameraCalibration(std::string_view text, const std::string& source);

// A EuRoC sensor.yaml for `camera` (which must pass Check(); throws std::invalid_argument
// otherwise). Numbers are written in shortest round-trip form, so reading the file back gives
// the same model. kNone is written as radial-tangential with zero coefficients (what EuRoC
// readers expect), which reads back as kNone; OpenCV's rational, thin-prism and tilted models
// as opencv_rational8, opencv_thin_prism12 and opencv_tilted14.
std::string FormatEuRoCSensorYaml(const CameraModel& camera,
                                  const Rigid3& body_from_cam = Rigid3::Identity());
// Writes FormatEuRoCSensorYaml() to `path` atomically.
void WriteEuRoCSensorYaml(const CameraModel& camera, const std::filesystem::path& path,
                          const Rigid3& body_from_cam = Rigid3::Identity());

}  // namespace arucoslam
