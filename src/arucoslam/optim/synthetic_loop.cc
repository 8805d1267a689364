#include "arucoslam/optim/synthetic_loop.h"

#include <cmath>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool SyntheticLoopOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("num_keyframes", num_keyframes, 3);
  check.Above("radius_m", radius_m, 0.0);
  check.Above("scale_drift", scale_drift, 0.0);
  check.AtLeast("covisibility_span", covisibility_span, 1);
  return check.ok();
}

SyntheticLoop MakeSyntheticLoop(const SyntheticLoopOptions& options) {
  SyntheticLoop loop;
  const int n = options.num_keyframes;
  // Truth: camera i at angle a_i on the circle, looking outwards (z radial), y down.
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * M_PI * i / n;
    const Eigen::Vector3d centre(options.radius_m * std::cos(angle), 0.0,
                                 options.radius_m * std::sin(angle));
    Eigen::Matrix3d world_from_cam;
    world_from_cam.col(2) = centre.normalized();
    world_from_cam.col(1) = Eigen::Vector3d(0.0, -1.0, 0.0);
    world_from_cam.col(0) = world_from_cam.col(1).cross(world_from_cam.col(2));
    loop.truth_cam_from_world.push_back(Rigid3(world_from_cam, centre).Inverse());
  }
  // Drifted odometry: each true step is rotated a little more and lengthened by the local
  // scale (1 at keyframe 0, scale_drift^i at keyframe i).
  std::vector<Rigid3> estimate = {loop.truth_cam_from_world[0]};
  const Rigid3 yaw_drift(
      Eigen::Quaterniond(Eigen::AngleAxisd(options.yaw_drift_rad, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d::Zero());
  double local_scale = 1.0;
  std::vector<double> local_scales = {1.0};
  for (int i = 0; i + 1 < n; ++i) {
    Rigid3 step = loop.truth_cam_from_world[i + 1] * loop.truth_cam_from_world[i].Inverse();
    step = yaw_drift * step;
    step.translation *= local_scale;
    estimate.push_back(step * estimate.back());
    local_scale *= options.scale_drift;
    local_scales.push_back(local_scale);
  }
  for (int i = 0; i < n; ++i) loop.problem.nodes.push_back({Sim3(estimate[i]), i == 0});
  for (int i = 0; i < n; ++i) {
    for (int d = 1; d <= options.covisibility_span && i + d < n; ++d) {
      PoseGraphProblem::Edge edge;
      edge.from = i;
      edge.to = i + d;
      edge.to_from_from = Sim3(estimate[i + d] * estimate[i].Inverse());
      loop.problem.edges.push_back(edge);
    }
  }
  // Loop: points near the last keyframe are scaled by its local scale in the estimate, so
  // the measured 0_from_last maps them back with 1 / local scale.
  PoseGraphProblem::Edge loop_edge;
  loop_edge.from = n - 1;
  loop_edge.to = 0;
  const double loop_scale = options.scale_in_loop_edge ? 1.0 / local_scales.back() : 1.0;
  loop_edge.to_from_from =
      Sim3(loop.truth_cam_from_world[0] * loop.truth_cam_from_world[n - 1].Inverse()) *
      Sim3(loop_scale, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero());
  loop.problem.edges.push_back(loop_edge);
  return loop;
}

double CameraCentreRms(const PoseGraphProblem& problem, const std::vector<Rigid3>& truth) {
  double sum = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Eigen::Vector3d centre = problem.nodes[i].cam_from_world.Inverse().translation;
    sum += (centre - truth[i].Inverse().translation).squaredNorm();
  }
  return truth.empty() ? 0.0 : std::sqrt(sum / truth.size());
}

}  // namespace arucoslam
