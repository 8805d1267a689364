// The SVG plots of `arucoslam eval` (declared in report.h).
#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "arucoslam/eval/report.h"
#include "arucoslam/eval/svg_plot.h"

namespace arucoslam {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const char* const kGroundTruthColor = "#222222";

// Values of pair i with a NaN inserted wherever tracking left a gap, so lines break there.
template <typename ValueOf>
void CollectWithGaps(const TrajectoryEvaluation& e, ValueOf value_of, std::vector<double>& x,
                     std::vector<double>& y, double time_origin, bool x_is_time) {
  const std::vector<double>& t = e.pairs.gt.timestamps;
  const double gap = e.completeness.max_gap_used;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (i > 0 && gap > 0.0 && t[i] - t[i - 1] > gap) {
      x.push_back(kNaN);
      y.push_back(kNaN);
    }
    const auto [xi, yi] = value_of(i);
    x.push_back(x_is_time ? t[i] - time_origin : xi);
    y.push_back(yi);
  }
}

std::string AlignmentSuffix(const std::vector<TrajectoryEvaluation>& evaluations) {
  return fmt::format("alignment: {}", AlignmentModeName(evaluations.front().alignment.mode));
}

// The two world axes along which the ground truth spreads most: x-y for a z-up world,
// x-z for a camera-frame world such as KITTI's (y down).
std::pair<int, int> ViewAxes(const Trajectory& gt) {
  Eigen::Vector3d low = gt.poses.front().translation;
  Eigen::Vector3d high = low;
  for (const Rigid3& pose : gt.poses) {
    low = low.cwiseMin(pose.translation);
    high = high.cwiseMax(pose.translation);
  }
  Eigen::Index flattest = 2;
  (high - low).minCoeff(&flattest);
  if (flattest == 0) return {1, 2};
  if (flattest == 1) return {0, 2};
  return {0, 1};
}

SvgPlot TopDownPlot(const Trajectory& gt, const std::vector<TrajectoryEvaluation>& evaluations) {
  const auto [u, v] = ViewAxes(gt);
  const char* names[] = {"x", "y", "z"};
  SvgPlot plot({fmt::format("Trajectory, view from above ({}-{} plane, {})", names[u], names[v],
                            AlignmentSuffix(evaluations)),
                fmt::format("{} [m]", names[u]), fmt::format("{} [m]", names[v]), 960, 760, true,
                false});
  std::vector<double> gx;
  std::vector<double> gy;
  for (const Rigid3& pose : gt.poses) {
    gx.push_back(pose.translation[u]);
    gy.push_back(pose.translation[v]);
  }
  plot.AddLine(gx, gy, "ground truth", kGroundTruthColor, 2.6, true);
  for (std::size_t k = 0; k < evaluations.size(); ++k) {
    const TrajectoryEvaluation& e = evaluations[k];
    std::vector<double> x;
    std::vector<double> y;
    CollectWithGaps(
        e,
        [&](std::size_t i) {
          const Eigen::Vector3d& p = e.aligned_est.poses[i].translation;
          return std::pair<double, double>(p[u], p[v]);
        },
        x, y, 0.0, false);
    plot.AddLine(x, y, e.label, SvgPlot::PaletteColor(k), 1.8);
  }
  // The start drawn larger so that it stays visible when the path ends where it began.
  plot.AddMarkers({gx.front()}, {gy.front()}, "start", "#2CA02C", 8.0);
  plot.AddMarkers({gx.back()}, {gy.back()}, "end", "#D62728", 4.5);
  return plot;
}

SvgPlot ApePlot(const Trajectory& gt, const std::vector<TrajectoryEvaluation>& evaluations) {
  SvgPlot plot({fmt::format("Absolute position error over time ({})", AlignmentSuffix(evaluations)),
                "time since the first ground-truth pose [s]", "position error [m]", 960, 520, false,
                true});
  for (std::size_t k = 0; k < evaluations.size(); ++k) {
    const TrajectoryEvaluation& e = evaluations[k];
    std::vector<double> x;
    std::vector<double> y;
    CollectWithGaps(
        e,
        [&](std::size_t i) { return std::pair<double, double>(0.0, e.ape_translation_errors[i]); },
        x, y, gt.timestamps.front(), true);
    plot.AddLine(x, y, fmt::format("{} (rmse {:.3f} m)", e.label, e.ape_translation.rmse),
                 SvgPlot::PaletteColor(k), 1.6);
  }
  return plot;
}

std::vector<SvgPlot> PerAxisPlots(const Trajectory& gt,
                                  const std::vector<TrajectoryEvaluation>& evaluations) {
  std::vector<SvgPlot> plots;
  const char* axes[] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    SvgPlot plot(
        {fmt::format("Per-axis absolute error |d{}| ({})", axes[a], AlignmentSuffix(evaluations)),
         "time since the first ground-truth pose [s]", fmt::format("|d{}| [m]", axes[a]), 960, 340,
         false, true});
    for (std::size_t k = 0; k < evaluations.size(); ++k) {
      const TrajectoryEvaluation& e = evaluations[k];
      std::vector<double> x;
      std::vector<double> y;
      CollectWithGaps(
          e,
          [&](std::size_t i) {
            const double d =
                e.aligned_est.poses[i].translation[a] - e.pairs.gt.poses[i].translation[a];
            return std::pair<double, double>(0.0, std::abs(d));
          },
          x, y, gt.timestamps.front(), true);
      plot.AddLine(x, y, fmt::format("{} (mean {:.3f} m)", e.label, e.per_axis.mean_abs[a]),
                   SvgPlot::PaletteColor(k), 1.4);
      std::vector<double> sx;
      std::vector<double> sy;
      for (const PerAxisSample& s : e.per_axis.samples) {
        if (!s.found) continue;
        sx.push_back(s.time - gt.timestamps.front());
        sy.push_back(s.abs_error[a]);
      }
      if (!sx.empty()) plot.AddMarkers(sx, sy, "", SvgPlot::PaletteColor(k), 4.5);
    }
    plots.push_back(plot);
  }
  return plots;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> MakeEvaluationPlots(
    const Trajectory& gt, const std::vector<TrajectoryEvaluation>& evaluations) {
  if (evaluations.empty() || gt.empty()) return {};
  return {{"trajectory_top_down.svg", TopDownPlot(gt, evaluations).Render()},
          {"ape_over_time.svg", ApePlot(gt, evaluations).Render()},
          {"per_axis_error.svg", RenderSvgDocument(PerAxisPlots(gt, evaluations))}};
}

}  // namespace arucoslam
