#include "arucoslam/sim/default_camera.h"

namespace arucoslam {

CameraModel DefaultSimulatorCamera() {
  CameraModel camera = PinholeCamera(640, 480, 460.0);
  camera.rate_hz = 30.0;
  return camera;
}

}  // namespace arucoslam
