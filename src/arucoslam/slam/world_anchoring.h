// WorldAnchoring: the keyframes' marker locations that tie the keypoint map to the marker world,
// when the map is aligned (and realigned) to them, and when they correct its drift.
#pragma once

#include <atomic>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/map/ids.h"
#include "arucoslam/map/map.h"
#include "arucoslam/optim/essential_graph.h"
#include "arucoslam/optim/marker_factors.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/world_alignment.h"

namespace arucoslam {

struct WorldAnchoringOptions {
  // The Sim3 fit of the map to the anchors. Anchor outliers beyond 0.25 m: a single marker's
  // pose at a few metres can be off by more than WorldAlignmentOptions' 0.10 m default allows.
  WorldAlignmentOptions alignment{0.0, 0.25, 0.05};
  // World alignment waits for this many keyframes with a usable marker location ...
  int min_alignment_anchors = 4;
  // ... whose camera centres span at least this, metres.
  double min_alignment_baseline_m = 0.5;
  // An alignment whose anchor residual exceeds this is refused, metres.
  double max_alignment_rms_m = 0.15;
  // A map starts with its median point depth 1: aligning it multiplies lengths by about the
  // scene's depth in metres. A first alignment's scale above this means the map collapsed
  // in scale before it saw markers; it is refused (a ratio).
  double max_alignment_scale = 100.0;
  // After the first alignment, anchors keep being collected and the map is aligned again
  // (a small Sim3 correction) each time their number doubles, up to this many anchors.
  int max_realignment_anchors = 64;
  // Drift correction: a keyframe of the aligned map whose keypoint pose lies farther than
  // min_marker_correction_m (metres, its centre) and than marker_correction_sigmas standard
  // deviations (the Mahalanobis distance over centre and rotation under marker_priors) from
  // its pose from its known markers triggers a pose-graph correction of the whole map, with
  // the marker pose of every keyframe that sees known markers as a prior. false: never.
  bool drift_correction = true;
  double min_marker_correction_m = 0.05;
  double marker_correction_sigmas = 3.0;
  // A keyframe's marker location as a prior: the covariance its corners give (1 px noise) plus
  // 1 cm and 0.01 rad per marker (divided by sqrt(markers)).
  MarkerFactorOptions marker_priors = [] {
    MarkerFactorOptions priors;
    priors.prior_position_sigma_m = 0.01;
    priors.prior_rotation_sigma_rad = 0.01;
    priors.prior_from_corners = true;
    return priors;
  }();
  // The pose graph of those corrections (and of loops and bridges corrected with the marker
  // priors): 2 cm, 0.005 rad and 1% scale per relative-pose edge.
  EssentialGraphOptions marker_correction_graph = [] {
    EssentialGraphOptions graph;
    graph.edge_translation_sigma = 0.02;
    graph.edge_rotation_sigma = 0.005;
    graph.edge_scale_sigma = 0.01;
    // A drift of metres (a map whose scale collapsed out of the markers' sight) needs more
    // than the solver's default 20 iterations; unconverged, the graph leaves the points torn
    // apart.
    graph.solver.max_iterations = 100;
    return graph;
  }();

  // A loop closed in the world-aligned map is corrected with the same marker priors and
  // graph weights (marker_correction_graph), no keyframe held fixed: the loop then keeps the
  // world anchoring.
  bool priors_in_loops = true;

  bool Check(std::string* why = nullptr) const;
};

struct WorldAnchoringStats {
  int num_alignments = 0;         // the map aligned (or realigned) to the marker world
  int num_drift_corrections = 0;  // pose-graph corrections of drift by markers
};

// An accepted alignment of the map to the marker world, and the anchors it was fitted to
// (alignment.inliers is per anchor).
struct AlignmentDecision {
  WorldAlignment alignment;
  std::vector<WorldAnchor> anchors;
};

// A drift correction to make: the marker priors of the pose graph, and why (for the log).
struct DriftCorrectionDecision {
  std::vector<KeyframePosePrior> priors;
  double offset_m = 0.0;       // the keyframe's keypoint centre from its marker location, metres
  double offset_sigmas = 0.0;  // its keypoint pose from that location, standard deviations
};

// One map's anchoring to the marker world. The tracking thread adds anchors and decides
// alignments; the keyframe fixes are also read by the mapping thread (guarded inside).
class WorldAnchoring {
 public:
  explicit WorldAnchoring(const WorldAnchoringOptions& options);

  const WorldAnchoringOptions& options() const { return options_; }
  bool aligned() const { return aligned_; }
  WorldAnchoringStats stats() const;
  // Mapping thread (keyframe culling): until the map is aligned, a keyframe that saw a marker
  // is kept, as it may carry an anchor.
  bool KeepsKeyframe(const Keyframe& keyframe) const {
    return !aligned_ && !keyframe.markers.empty();
  }

  // A new keyframe with its marker location (none: nothing to remember).
  void AddAnchor(KeyframeId keyframe, const std::optional<MarkerFix>& fix);
  // The alignment to apply now, or none (too few anchors with keyframes in `map`, too short a
  // baseline, a residual or first scale too large). Anchors whose keyframe left the map are
  // forgotten.
  std::optional<AlignmentDecision> DecideAlignment(const Map& map);
  // Before `decision` is applied: its outlier anchors (wrong marker locations) no longer
  // correct drift.
  void DropOutlierFixes(const AlignmentDecision& decision);
  // `decision` was applied: the map is aligned; the next realignment waits for twice its
  // anchors.
  void AlignmentApplied(const AlignmentDecision& decision);
  // The map entered the world another way (marker initialisation): realigned as anchors come.
  void AlignedFromMarkers();
  // No realignment any more (a merged map linked to this one, or a loaded aligned map).
  void StopRealigning();
  // A loaded map, aligned or not.
  void StartLoadedMap(bool aligned);
  // A new empty map: no anchors, no fixes, not aligned.
  void Reset();

  // Keyframe marker locations: all of them (a closing map keeps them) and those of a merged map.
  std::map<KeyframeId, MarkerFix> KeyframeFixes() const;
  void AddKeyframeFixes(const std::map<KeyframeId, MarkerFix>& fixes);

  // The pose-graph prior of a keyframe from its marker location (marker_priors).
  KeyframePosePrior MarkerPrior(KeyframeId keyframe, const MarkerFix& fix) const;
  // The priors of every keyframe located by known markers alone (drift correction, loops).
  std::vector<KeyframePosePrior> KnownMarkerPriors() const;
  // Mapping thread: whether `keyframe`'s known markers disagree with its pose in `map` enough
  // for a pose-graph correction.
  std::optional<DriftCorrectionDecision> DecideDriftCorrection(const Map& map,
                                                               KeyframeId keyframe) const;
  // Mapping thread: the correction DecideDriftCorrection asked for moved the map.
  void DriftCorrected() { ++num_drift_corrections_; }

 private:
  struct MarkerAnchor {
    KeyframeId keyframe;
    Rigid3 world_from_cam;
  };

  WorldAnchoringOptions options_;
  std::atomic<bool> aligned_{false};  // also read by the mapping thread (KeepsKeyframe)
  std::vector<MarkerAnchor> anchors_;
  int next_alignment_anchors_ = 0;  // alignment is tried again at this many anchors
  // The marker location of every keyframe inserted with one (the tracking thread writes, the
  // mapping thread reads for drift correction).
  mutable std::mutex fixes_mutex_;
  std::map<KeyframeId, MarkerFix> keyframe_fixes_;
  std::atomic<int> num_alignments_{0};
  std::atomic<int> num_drift_corrections_{0};  // counted by the mapping thread
};

}  // namespace arucoslam
