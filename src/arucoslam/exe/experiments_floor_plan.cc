#include "arucoslam/exe/experiments_floor_plan.h"

#include <cmath>
#include <limits>
#include <numbers>

#include "arucoslam/eval/alignment.h"
#include "arucoslam/eval/svg_plot.h"
#include "arucoslam/sim/world_model.h"

namespace arucoslam {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Footprints larger than this on both sides (floor, ceiling) would hide the plan.
constexpr double kMaxFootprintM = 15.0;
// Poses farther apart in time are not joined (a tracking gap).
constexpr double kMaxJoinedGapS = 0.5;

// Appends the closed outline of the primitive's footprint (x-y plane) to `x`, `y`, then a
// NaN that separates it from the next one.
void AddFootprint(const WorldPrimitive& primitive, std::vector<double>& x, std::vector<double>& y) {
  std::vector<Eigen::Vector3d> outline;
  if (primitive.type == ShapeType::kCylinder) {
    for (int k = 0; k <= 24; ++k) {
      const double a = 2.0 * std::numbers::pi * k / 24;
      outline.emplace_back(primitive.radius() * std::cos(a), primitive.radius() * std::sin(a), 0.0);
    }
  } else {
    const double hx = 0.5 * primitive.size.x();
    const double hy = 0.5 * primitive.size.y();
    if (2.0 * hx > kMaxFootprintM && 2.0 * hy > kMaxFootprintM) return;
    outline = {{-hx, -hy, 0.0}, {hx, -hy, 0.0}, {hx, hy, 0.0}, {-hx, hy, 0.0}, {-hx, -hy, 0.0}};
  }
  for (const Eigen::Vector3d& corner : outline) {
    const Eigen::Vector3d p = primitive.world_from_shape * corner;
    x.push_back(p.x());
    y.push_back(p.y());
  }
  x.push_back(kNaN);
  y.push_back(kNaN);
}

void AddTrajectory(SvgPlot& plot, const Trajectory& trajectory, const std::string& label,
                   const std::string& color, double width, bool dashed) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    if (i > 0 && trajectory.timestamps[i] - trajectory.timestamps[i - 1] > kMaxJoinedGapS) {
      x.push_back(kNaN);
      y.push_back(kNaN);
    }
    x.push_back(trajectory.poses[i].translation.x());
    y.push_back(trajectory.poses[i].translation.y());
  }
  plot.AddLine(x, y, label, color, width, dashed);
}

}  // namespace

std::string FloorPlanSvg(const std::filesystem::path& world_sdf, const Trajectory& ground_truth,
                         const std::vector<ExperimentRun>& runs) {
  const WorldModel world = LoadWorldModel(world_sdf);
  SvgPlot plot({"Floor plan (top view): ground truth, trajectories and keyframes", "x [m]",
                "y [m]", 1100, 800, /*equal_aspect=*/true});
  std::vector<double> plan_x, plan_y;
  for (const WorldPrimitive& primitive : world.primitives) AddFootprint(primitive, plan_x, plan_y);
  plot.AddLine(plan_x, plan_y, "world (footprints)", "#b0b0b0", 0.8);
  AddTrajectory(plot, ground_truth, "ground truth", "#000000", 1.2, /*dashed=*/true);
  std::size_t color = 0;
  for (const ExperimentRun& run : runs) {
    const std::optional<TrajectoryEvaluation>& evaluation = run.in_world_frame ? run.absolute : run.sim3;
    if (!evaluation || run.keyframes < 0) continue;  // SLAM runs only
    const std::string colour = SvgPlot::PaletteColor(color++);
    const std::string frame = run.in_world_frame ? "" : " (Sim3-aligned)";
    AddTrajectory(plot, evaluation->aligned_est, run.label + frame, colour, 1.6, false);
    const Trajectory keyframes = ApplyAlignment(evaluation->alignment.gt_from_est, run.keyframe_poses);
    std::vector<double> x, y;
    for (const Rigid3& pose : keyframes.poses) {
      x.push_back(pose.translation.x());
      y.push_back(pose.translation.y());
    }
    plot.AddMarkers(x, y, "keyframes of " + run.label, colour, 2.5);
  }
  return plot.Render();
}

}  // namespace arucoslam
