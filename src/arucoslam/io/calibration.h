// Camera calibration files: reads a CameraModel from a EuRoC sensor.yaml, an ORB-SLAM3-style
// settings YAML or a ROS camera_info YAML (format found from the keys); writes sensor.yaml.
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
  kRosCameraInfo,  // ROS camera_info: image_width, camera_matrix.data (or K, or fx ...)
};

std::string CalibrationFormatName(CalibrationFormat format);

// What a calibration file says about one camera.
struct CameraCalibration {
  CameraModel camera;
  // The camera's mounting where the file gives it (EuRoC T_BS, ORB-SLAM3 Tbc or
  // IMU.T_b_c1), else identity.
  Rigid3 body_from_cam;
  CalibrationFormat format = CalibrationFormat::kEuRoC;
};

// Reads a calibration file of any of the three formats. Distortion coefficients that are all
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
// readers expect), which reads back as kNone.
std::string FormatEuRoCSensorYaml(const CameraModel& camera,
                                  const Rigid3& body_from_cam = Rigid3::Identity());
// Writes FormatEuRoCSensorYaml() to `path` atomically.
void WriteEuRoCSensorYaml(const CameraModel& camera, const std::filesystem::path& path,
                          const Rigid3& body_from_cam = Rigid3::Identity());

}  // namespace arucoslam
