#include "arucoslam/optim/radial_refinement.h"

namespace arucoslam {

std::optional<CameraModel> WithRadialTerm(const CameraModel& camera, double k) {
  if (camera.model == DistortionModel::kEquidistant) return std::nullopt;
  CameraModel corrected = camera;
  if (corrected.model == DistortionModel::kNone) corrected.model = DistortionModel::kRadTan;
  corrected.distortion[0] += k;
  return corrected;
}

}  // namespace arucoslam
