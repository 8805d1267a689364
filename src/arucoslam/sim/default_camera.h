// The simulator's default camera (what `simulate` and `experiments` render with unless a
// calibration file is given): 640x480 pinhole, 460 px focal length, no distortion, 30 Hz.
#pragma once

#include "arucoslam/geometry/camera.h"

namespace arucoslam {

CameraModel DefaultSimulatorCamera();

}  // namespace arucoslam
