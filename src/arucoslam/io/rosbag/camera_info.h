// The camera of a sensor_msgs/CameraInfo message as a CameraModel (plumb_bob -> radial-
// tangential, equidistant -> fisheye), read through io/calibration's ROS camera_info parser
// so that a bag's or topic's camera passes the same checks as a camera_info file.
#pragma once

#include <sensor_msgs/CameraInfo.h>
#include <string>

#include "arucoslam/geometry/camera.h"

namespace arucoslam {

// Throws InputError naming `source` (bag and topic, or the topic) and the field at fault:
// zero size, an uncalibrated all-zero K, skew, a distortion model the camera models lack
// (e.g. rational_polynomial), a wrong number of coefficients. An empty D means no distortion.
CameraModel CameraFromInfo(const sensor_msgs::CameraInfo& info, const std::string& source);

// The camera_info YAML text CameraFromInfo parses (image_width, image_height,
// distortion_model, K, D), numbers in shortest round-trip form.
std::string CameraInfoYaml(const sensor_msgs::CameraInfo& info);

// A CameraInfo message of `camera` (R identity, P = [K | 0]) (tests, bag writing).
sensor_msgs::CameraInfo CameraInfoFromModel(const CameraModel& camera);

}  // namespace arucoslam
