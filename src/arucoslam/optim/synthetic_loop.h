// Synthetic loop for pose-graph tests and benchmarks: keyframes on a circle, odometry with
// accumulated rotation and scale drift, covisibility edges and one loop edge back to the start.
#pragma once

#include <string>
#include <vector>

#include "arucoslam/optim/pose_graph.h"

namespace arucoslam {

struct SyntheticLoopOptions {
  int num_keyframes = 40;          // around one circle
  double radius_m = 10.0;          // circle radius, metres
  double yaw_drift_rad = 0.01;     // extra rotation per step (about the camera's y axis)
  double scale_drift = 1.01;       // step lengths grow by this factor per keyframe
  int covisibility_span = 2;       // edges i -> i+1 .. i+span (span >= 1)
  bool scale_in_loop_edge = true;  // monocular: the loop edge carries the scale drift

  bool Check(std::string* why = nullptr) const;
};

struct SyntheticLoop {
  std::vector<Rigid3> truth_cam_from_world;  // per keyframe
  // Nodes: the drifted estimate (node 0 exact and fixed); edges: relative poses of that
  // estimate between keyframes up to `covisibility_span` apart, then the loop edge
  // (last -> 0) from the truth as a Sim3 solver would measure it.
  PoseGraphProblem problem;
};

SyntheticLoop MakeSyntheticLoop(const SyntheticLoopOptions& options);

// RMS distance (metres) between the camera centres of the nodes and of the truth.
double CameraCentreRms(const PoseGraphProblem& problem, const std::vector<Rigid3>& truth);

}  // namespace arucoslam
