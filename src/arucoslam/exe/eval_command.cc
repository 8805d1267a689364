// `arucoslam eval`: compares one or several estimated trajectories with ground truth (ATE,
// RPE, per-axis error, scale, completeness, map accuracy), prints a table and writes
// results.json and SVG plots to --out.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "arucoslam/eval/evaluation.h"
#include "arucoslam/eval/ply_points.h"
#include "arucoslam/eval/report.h"
#include "arucoslam/eval/world_surfaces.h"
#include "arucoslam/exe/command.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

struct EvalArgs {
  std::string gt;
  std::vector<std::string> est;
  std::vector<std::string> labels;
  std::string align = "none";
  int align_first = 0;
  std::vector<double> align_window;  // seconds from the first ground-truth pose
  double max_diff = 0.01;            // seconds
  bool by_index = false;
  std::vector<std::string> rpe = {"1frames"};
  std::vector<double> at;  // seconds from the first ground-truth pose
  double max_gap = 0.0;    // seconds, 0 = automatic
  double scale_window = 0.0;  // seconds, 0 = no scale drift
  std::vector<std::string> stats;
  std::vector<std::string> maps;
  std::string world;
  std::string out;
};

// "1frames", "10m", "2s", "5f" -> options; InputError("--rpe") otherwise.
RelativeErrorOptions ParseRpeDelta(const std::string& text) {
  std::size_t used = 0;
  RelativeErrorOptions options;
  try {
    options.delta = std::stod(text, &used);
  } catch (const std::logic_error&) {
    used = 0;
  }
  const std::string unit = text.substr(used);
  if (unit == "frames" || unit == "frame" || unit == "f") {
    options.unit = DeltaUnit::kFrames;
  } else if (unit == "m") {
    options.unit = DeltaUnit::kMeters;
  } else if (unit == "s") {
    options.unit = DeltaUnit::kSeconds;
  } else {
    used = 0;
  }
  if (used == 0 || !options.Check()) {
    throw InputError("--rpe", "cannot read '" + text +
                                  "' (expected a positive number and a unit: 1frames, 10m, 2s)");
  }
  return options;
}

EvaluationOptions MakeOptions(const EvalArgs& args, double gt_start) {
  EvaluationOptions options;
  const std::optional<AlignmentMode> mode = ParseAlignmentMode(args.align);
  if (!mode) throw InputError("--align", "expected none, se3 or sim3, found '" + args.align + "'");
  options.alignment.mode = *mode;
  if (args.align_first < 0) throw InputError("--align-first", "expected a count >= 0");
  options.alignment.first_poses = args.align_first;
  if (!args.align_window.empty()) {
    if (args.align_window.size() != 2 || !(args.align_window[1] > args.align_window[0])) {
      throw InputError("--align-window", "expected START END seconds with START < END");
    }
    options.alignment.window_start = gt_start + args.align_window[0];
    options.alignment.window_end = gt_start + args.align_window[1];
  }
  if (!(args.max_diff >= 0.0) || !std::isfinite(args.max_diff)) {
    throw InputError("--max-diff", "expected a time difference >= 0 seconds");
  }
  options.association.max_time_difference = args.max_diff;
  options.associate_by_index = args.by_index;
  options.relative.clear();
  for (const std::string& delta : args.rpe) options.relative.push_back(ParseRpeDelta(delta));
  for (double t : args.at) options.per_axis.timestamps.push_back(gt_start + t);
  if (!(args.max_gap >= 0.0)) throw InputError("--max-gap", "expected seconds >= 0");
  options.completeness.max_gap = args.max_gap;
  if (!(args.scale_window >= 0.0) || !std::isfinite(args.scale_window)) {
    throw InputError("--scale-window", "expected seconds >= 0");
  }
  if (args.scale_window > 0.0) {
    options.scale_drift = ScaleDriftOptions{};
    options.scale_drift->window_s = args.scale_window;
  }
  return options;
}

void CheckListLengths(const EvalArgs& args) {
  const auto check = [&](const std::vector<std::string>& list, const char* name) {
    if (!list.empty() && list.size() != args.est.size()) {
      throw InputError(name, "give one per --est (" + std::to_string(args.est.size()) +
                                 "), found " + std::to_string(list.size()));
    }
  };
  check(args.labels, "--label");
  check(args.stats, "--stats");
  check(args.maps, "--map");
  if (!args.maps.empty() && args.world.empty()) {
    throw InputError("--map", "map accuracy needs the true world: add --world WORLD.sdf");
  }
}

void WriteOutputs(const EvalArgs& args, const Trajectory& gt,
                  const std::vector<TrajectoryEvaluation>& evaluations,
                  const EvaluationOptions& options, const std::string& table) {
  StagedDirectory out(args.out);
  WriteTextFileAtomically(out.path() / "results.json",
                          FormatResultsJson(evaluations, args.est, args.gt, options));
  WriteTextFileAtomically(out.path() / "table.txt", table);
  for (const auto& [name, svg] : MakeEvaluationPlots(gt, evaluations)) {
    WriteTextFileAtomically(out.path() / name, svg);
  }
  out.Commit();
  std::printf(
      "wrote %s: results.json, table.txt, trajectory_top_down.svg, ape_over_time.svg, "
      "per_axis_error.svg\n",
      args.out.c_str());
}

void RunEval(const EvalArgs& args) {
  CheckListLengths(args);
  const Trajectory gt = ReadTrajectory(args.gt);
  const EvaluationOptions options = MakeOptions(args, gt.timestamps.front());
  std::vector<SurfacePrimitive> surfaces;
  if (!args.world.empty()) surfaces = LoadWorldSurfaces(args.world);
  std::vector<TrajectoryEvaluation> evaluations;
  for (std::size_t i = 0; i < args.est.size(); ++i) {
    const Trajectory est = ReadTrajectory(args.est[i]);
    const std::string label =
        args.labels.empty() ? fs::path(args.est[i]).stem().string() : args.labels[i];
    TrajectoryEvaluation evaluation = EvaluateTrajectory(gt, est, label, args.est[i], options);
    const std::size_t shorter = std::min(gt.size(), est.size());
    if (2 * evaluation.pairs.size() < shorter) {
      ARUCOSLAM_LOG_WARN(
          "{}: only {} of {} poses paired with the ground truth within {} s (a KITTI file "
          "without time needs --by-index or a <name>_times.txt beside it)",
          args.est[i], evaluation.pairs.size(), shorter, args.max_diff);
    }
    if (!args.stats.empty()) evaluation.tracking = ReadRunStats(args.stats[i]);
    if (!args.maps.empty()) {
      evaluation.map =
          ComputeMapAccuracy(ReadPlyPoints(args.maps[i]), evaluation.alignment.gt_from_est,
                             surfaces, MapAccuracyOptions{});
    }
    evaluations.push_back(std::move(evaluation));
  }
  const std::string table = FormatEvaluationTable(evaluations);
  std::fputs(table.c_str(), stdout);
  if (!args.out.empty()) WriteOutputs(args, gt, evaluations, options, table);
}

}  // namespace

void AddEvalCommand(CLI::App& app, int& exit_status) {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* eval = app.add_subcommand(
      "eval",
      "ATE / RPE / per-axis error, scale and completeness of trajectories against "
      "ground truth (TUM, EuRoC csv or KITTI files; evo's definitions)");
  eval->add_option("--gt", args->gt, "ground-truth trajectory (TUM, EuRoC csv, KITTI)")->required();
  eval->add_option("--est", args->est, "estimated trajectory; repeat to compare several")
      ->required();
  eval->add_option("--label", args->labels, "name of each estimate (default: file stem)");
  eval->add_option("--align", args->align, "alignment before APE: none, se3 or sim3")
      ->capture_default_str();
  eval->add_option("--align-first", args->align_first,
                   "fit the alignment on the first N pose pairs only (0: all)")
      ->capture_default_str();
  eval->add_option("--align-window", args->align_window,
                   "fit the alignment on pairs in START END (seconds from the first "
                   "ground-truth pose)")
      ->expected(2);
  eval->add_option("--max-diff", args->max_diff, "largest time difference for a pose pair, seconds")
      ->capture_default_str();
  eval->add_flag("--by-index", args->by_index,
                 "pair pose i with pose i (files without time, e.g. KITTI)");
  eval->add_option("--rpe", args->rpe, "RPE delta(s): e.g. 1frames, 10m, 2s")
      ->capture_default_str();
  eval->add_option("--at", args->at,
                   "times (seconds from the first ground-truth pose) at which to report the "
                   "per-axis error");
  eval->add_option("--max-gap", args->max_gap,
                   "completeness: poses further apart leave a gap, seconds (0: 3x the median "
                   "frame interval)")
      ->capture_default_str();
  eval->add_option("--scale-window", args->scale_window,
                   "scale drift: the Sim(3) scale over consecutive windows of this many seconds "
                   "(0: off); a monocular map growing or shrinking as it goes")
      ->capture_default_str();
  eval->add_option("--stats", args->stats,
                   "a run's stats.json per --est: {\"tracking\": {\"losses\": N, "
                   "\"relocalisations\": M}}");
  eval->add_option("--map", args->maps, "map points (ASCII PLY) per --est, for map accuracy");
  eval->add_option("--world", args->world, "the true world (SDF) for map accuracy");
  eval->add_option("--out", args->out,
                   "output folder (replaced): results.json, table.txt and SVG plots");
  eval->callback([args, &exit_status] {
    RunEval(*args);
    exit_status = kExitOk;
  });
}

}  // namespace arucoslam
