#include "arucoslam/sim/default_camera.h"

namespace arucoslam {

CameraModel DefaultSimulatorCamera() {
  CameraModel camera;
  camera.width = 640;
  camera.height = 480;
  camera.fx = camera.fy = 460.0;
  camera.cx = 319.5;
  camera.cy = 239.5;
  camera.rate_hz = 30.0;
  return camera;
}

}  // namespace arucoslam
