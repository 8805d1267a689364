// GroundPlaneError: the soft prior of a camera on a ground vehicle driving a level floor, whose
// height above the world's z = 0 and tilt from the world's vertical stay the same.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

// How far a ground vehicle's camera strays from its plane: floor unevenness and suspension
// travel (height) and pitch and roll wobble (tilt). The world frame is z-up with a level floor.
struct GroundPlanePriorOptions {
  double height_sigma_m = 0.01;
  double tilt_sigma_rad = 0.005;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("height_sigma_m", height_sigma_m, 0.0);
    check.Above("tilt_sigma_rad", tilt_sigma_rad, 0.0);
    return check.ok();
  }
};

// The plane a ground vehicle's camera moves in: its height (world z of the camera centre) and
// the world's up direction in camera coordinates (unit; the mounting tilt).
struct GroundPlane {
  double height_m = 0.0;
  Eigen::Vector3d up_in_camera = Eigen::Vector3d::Zero();
};

// The mean plane of a set of poses: mean camera-centre height, mean up direction (normalised).
// Zero for no poses.
GroundPlane MeanGroundPlane(const std::vector<Rigid3>& cams_from_world);

using GroundPlanePoseJacobian = Eigen::Matrix<double, 3, 6>;
using GroundPlaneHeightJacobian = Eigen::Matrix<double, 3, 1>;
using GroundPlaneUpJacobian = Eigen::Matrix<double, 3, 3>;

// Whitened residual r = [(c_z - height) / sigma_h; (R_wc up).x / sigma_t; (R_wc up).y / sigma_t]
// for a camera with centre c and world_from_cam rotation R_wc: zero when the camera sits at
// the plane's height with the plane's up direction along world z. Jacobians (pointers may be
// null) w.r.t. the left perturbation of cam_from_world ([upsilon; omega] as in Rigid3::Exp),
// the height and the up vector (ambient, 3 columns).
class GroundPlaneError {
 public:
  explicit GroundPlaneError(const GroundPlanePriorOptions& options)
      : inverse_height_sigma_(1.0 / options.height_sigma_m),
        inverse_tilt_sigma_(1.0 / options.tilt_sigma_rad) {}

  void Evaluate(const Rigid3& cam_from_world, const GroundPlane& plane, Eigen::Vector3d* residual,
                GroundPlanePoseJacobian* d_pose = nullptr,
                GroundPlaneHeightJacobian* d_height = nullptr,
                GroundPlaneUpJacobian* d_up = nullptr) const;

 private:
  double inverse_height_sigma_;
  double inverse_tilt_sigma_;
};

}  // namespace arucoslam
