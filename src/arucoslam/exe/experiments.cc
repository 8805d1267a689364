#include "arucoslam/exe/experiments.h"

#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <optional>

#include "arucoslam/exe/default_vocabulary.h"
#include "arucoslam/exe/experiments_report.h"
#include "arucoslam/exe/marker_only_run.h"
#include "arucoslam/exe/slam_run.h"
#include "arucoslam/eval/world_surfaces.h"
#include "arucoslam/feature/vocabulary.h"
#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/io/path_json.h"
#include "arucoslam/sim/default_camera.h"
#include "arucoslam/sim/path.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

std::vector<TimedPose> RepeatRunPoses(const fs::path& world_dir, double max_seconds) {
  const PathSpec spec = ReadPathJson(world_dir / "path.json");
  std::vector<TimedPose> poses = GenerateCameraPath(spec, PathRun::kRepeat);
  if (max_seconds > 0.0) {
    while (!poses.empty() && poses.back().time_s > max_seconds) poses.pop_back();
  }
  if (poses.size() < 3) throw InputError((world_dir / "path.json").string(), "route too short");
  return poses;
}

fs::path RenderSequence(const fs::path& world_dir, const std::vector<TimedPose>& poses,
                        const fs::path& out, const ExperimentsOptions& options) {
  RequireFile(world_dir / "world.sdf", "world file");
  DatasetWriterOptions render = options.render;
  render.progress = options.progress;
  if (options.progress) std::fprintf(stderr, "rendering %s\n", out.string().c_str());
  WriteSimulatedSequence(world_dir / "world.sdf", DefaultSimulatorCamera(), poses, out, render);
  return out;
}

EvaluationOptions AbsoluteOptions() {
  EvaluationOptions options;
  options.association.max_time_difference = 1e-4;  // same frames: stamps are identical
  return options;
}

EvaluationOptions Sim3Options() {
  EvaluationOptions options = AbsoluteOptions();
  options.alignment.mode = AlignmentMode::kSim3;
  return options;
}

// Evaluates `est` when it has enough poses; otherwise the run keeps a note.
void Evaluate(const Trajectory& gt, const Trajectory& est, bool with_sim3, ExperimentRun& run) {
  if (est.size() < 3) {
    run.note += (run.note.empty() ? "" : "; ") + fmt::format("only {} poses", est.size());
    return;
  }
  run.absolute = EvaluateTrajectory(gt, est, run.label, run.label, AbsoluteOptions());
  if (with_sim3) run.sim3 = EvaluateTrajectory(gt, est, run.label, run.label, Sim3Options());
}

// A SLAM run's counts, keyframes and map accuracy (after the alignment of `evaluation`,
// against the surfaces of the sequence's world.sdf when it has one).
void AddSlamResults(const SlamRunResult& result, const fs::path& sequence,
                    const std::optional<TrajectoryEvaluation>& evaluation, ExperimentRun& run) {
  run.losses = result.stats.losses;
  run.new_maps = result.timing.map_session.num_new_maps_after_loss;
  run.keyframes = static_cast<int>(result.keyframes.size());
  run.keyframe_poses = result.keyframes;
  const fs::path world = sequence / "world.sdf";
  if (!evaluation || result.map_points.empty() || !fs::exists(world)) return;
  run.map_accuracy = ComputeMapAccuracy(result.map_points, evaluation->alignment.gt_from_est,
                                        LoadWorldSurfaces(world), MapAccuracyOptions{});
}

// The sequence's markers.json; without one, nullopt and the run's note says so.
std::optional<MarkerMap> SequenceMarkerMap(const Dataset& dataset, ExperimentRun& run) {
  const std::optional<fs::path> path = dataset.markers_path();
  if (!path) {
    run.note = "the sequence has no markers.json";
    return std::nullopt;
  }
  return ReadMarkerMapJson(*path);
}

ExperimentRun MarkerOnlyRun(const fs::path& sequence, const fs::path& out_dir, bool progress) {
  ExperimentRun run;
  run.label = "markers only (no SLAM)";
  run.sequence = "with markers";
  const Dataset dataset = Dataset::Open(sequence);
  const std::optional<MarkerMap> markers = SequenceMarkerMap(dataset, run);
  if (!markers) return run;
  MarkerOnlyOptions options;
  options.progress = progress;
  const MarkerOnlyResult result = RunMarkerOnly(dataset, *markers, options);
  run.available = true;
  run.median_frame_ms = result.detection_ms.Summarize().median;
  run.note = fmt::format("{} of {} frames see a known marker; {} ambiguous single-marker views left out",
                         result.frames_with_markers, result.frames, result.ambiguous_skipped);
  WriteTumTrajectory(out_dir / "markers_only.tum", result.trajectory);
  Evaluate(dataset.ground_truth(), result.trajectory, /*with_sim3=*/false, run);
  return run;
}

// ArucoSLAM: keypoints and the sequence's known markers.
ExperimentRun MarkerSlamRun(const fs::path& sequence, const fs::path& out_dir,
                            const SystemOptions& slam, bool progress) {
  ExperimentRun run;
  run.label = "1: ArucoSLAM (markers + keypoints)";
  run.sequence = "with markers";
  const Dataset dataset = Dataset::Open(sequence);
  const std::optional<MarkerMap> markers = SequenceMarkerMap(dataset, run);
  if (!markers) return run;
  SystemOptions options = slam;
  options.marker_map = *markers;
  options.detector.dictionary = options.marker_map->dictionary;
  if (progress) std::fprintf(stderr, "SLAM, %s\n", run.label.c_str());
  const SlamRunResult result =
      RunSlamOnDataset(dataset, sequence.string(), options, /*markers=*/true, out_dir, progress);
  run.available = true;
  run.median_frame_ms = result.timing.frame_ms.Summarize().median;
  run.note = fmt::format(
      "{} of {} frames with a pose ({} from markers alone; of those without, {} saw no marker), "
      "{} losses, {} marker "
      "relocalisations, {} world alignments ({} maps initialised from markers), {} new maps "
      "after a loss ({} never aligned, left out), {} keyframes, {} map points in the last map{}",
      result.stats.frames_tracked, result.stats.frames, result.timing.num_marker_only_poses,
      result.timing.num_unposed_without_markers, result.stats.losses, result.timing.num_marker_relocalizations,
      result.timing.world_anchoring.num_alignments, result.timing.num_marker_initializations,
      result.timing.map_session.num_new_maps_after_loss,
      result.timing.map_session.num_maps_discarded, result.stats.keyframes, result.stats.map_points,
      options.marker_mapping.ground_plane_prior
          ? "; ground-vehicle prior (keyframes held near one camera height and tilt in the "
            "whole-map adjustment)"
          : "");
  Evaluate(dataset.ground_truth(), result.trajectory, /*with_sim3=*/true, run);
  AddSlamResults(result, sequence, run.absolute, run);
  return run;
}

// Keypoint-only SLAM on one rendered sequence.
ExperimentRun KeypointSlamRun(const std::string& label, const std::string& sequence_name,
                              const fs::path& sequence, const fs::path& out_dir,
                              const SystemOptions& slam, bool progress) {
  ExperimentRun run;
  run.label = label;
  run.sequence = sequence_name;
  const Dataset dataset = Dataset::Open(sequence);
  if (progress) std::fprintf(stderr, "SLAM, %s\n", label.c_str());
  const SlamRunResult result =
      RunSlamOnDataset(dataset, sequence.string(), slam, /*markers=*/false, out_dir, progress);
  run.available = true;
  run.median_frame_ms = result.timing.frame_ms.Summarize().median;
  run.note = fmt::format(
      "{} of {} frames tracked, {} losses, {} new maps after a loss (the output is the map "
      "with the most keyframes), {} keyframes, {} map points in the last map",
      result.stats.frames_tracked, result.stats.frames, result.stats.losses,
      result.timing.map_session.num_new_maps_after_loss, result.stats.keyframes,
      result.stats.map_points);
  Evaluate(dataset.ground_truth(), result.trajectory, /*with_sim3=*/true, run);
  run.in_world_frame = false;
  AddSlamResults(result, sequence, run.sim3, run);
  return run;
}

}  // namespace

ExperimentsResult RunExperiments(const ExperimentsOptions& options) {
  if (std::string why; !options.Check(&why)) {
    throw InputError("experiments", "invalid options: " + why);
  }
  RequireDirectory(options.world_dir, "world folder");
  const std::vector<TimedPose> poses = RepeatRunPoses(options.world_dir, options.max_seconds);
  // Loaded before anything is rendered: a bad vocabulary fails fast.
  const std::shared_ptr<const Vocabulary> vocabulary = std::make_shared<const Vocabulary>(
      Vocabulary::Load(options.vocabulary.empty() ? DefaultVocabularyPath() : options.vocabulary));
  // Every run is blocking (deterministic) and otherwise the SLAM `arucoslam run` runs.
  const SystemOptions slam = DefaultRunOptions(/*blocking=*/true, vocabulary, options.loop_closing);

  StagedDirectory staged(options.out_dir);
  const fs::path with_markers =
      RenderSequence(options.world_dir, poses, staged.path() / "seq_with_markers", options);
  std::optional<fs::path> without_markers;
  if (options.world_without_markers_dir) {
    without_markers = RenderSequence(*options.world_without_markers_dir, poses,
                                     staged.path() / "seq_without_markers", options);
  }

  ExperimentsResult result;
  SystemOptions run1_slam = slam;
  if (options.ground_vehicle) {
    run1_slam.marker_mapping.ground_plane_prior = GroundPlanePriorOptions{};
  }
  result.runs.push_back(
      MarkerSlamRun(with_markers, staged.path() / "run1_arucoslam", run1_slam, options.progress));
  result.runs.push_back(KeypointSlamRun("2: keypoints only, markers in scene", "with markers",
                                        with_markers, staged.path() / "run2_keypoints_with_markers",
                                        slam, options.progress));
  if (without_markers) {
    result.runs.push_back(KeypointSlamRun("3: keypoints only, no markers", "without markers",
                                          *without_markers,
                                          staged.path() / "run3_keypoints_without_markers",
                                          slam, options.progress));
  } else {
    ExperimentRun run;
    run.label = "3: keypoints only, no markers";
    run.sequence = "without markers";
    run.note = "no world without markers was given";
    result.runs.push_back(run);
  }
  result.runs.push_back(MarkerOnlyRun(with_markers, staged.path(), options.progress));

  const Dataset reference = Dataset::Open(with_markers);
  result.table = FormatExperimentsTable(result.runs);
  const std::string world =
      !options.world_description.empty()
          ? options.world_description
          : fmt::format("{}, {} markers in its markers.json", options.world_dir.string(),
                        reference.markers_path() ? ReadMarkerMapJson(*reference.markers_path())
                                                       .markers.size()
                                                 : 0u);
  WriteExperimentsReport(reference.ground_truth(), result.runs, result.table, staged.path(),
                         with_markers / "world.sdf", world);
  staged.Commit();
  return result;
}

}  // namespace arucoslam
