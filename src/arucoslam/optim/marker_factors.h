// Marker factors for keyframe optimisations: the corner observations a MarkerLandmarks holds
// for the keyframes of a bundle adjustment (known markers fixed, mapped ones estimated), the
// joint solve, and marker pose priors for a pose graph. Shared by local and global BA.
#pragma once

#include <string>
#include <vector>

#include "arucoslam/map/map_data.h"
#include "arucoslam/map/marker_landmark.h"
#include "arucoslam/optim/bundle_adjustment.h"
#include "arucoslam/optim/essential_graph.h"
#include "arucoslam/optim/marker_bundle_adjustment.h"
#include "arucoslam/optim/pose_graph.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct MarkerFactorOptions {
  double corner_sigma_px = 1.0;  // corner noise given to the solver, pixels
  // Marker residual robustness and outlier test (see MarkerBundleAdjustmentOptions).
  double marker_huber_delta = 3.937892;
  double marker_chi_square_threshold = kChiSquare8Dof95;
  // Pose priors (MarkerPosePriors): a keyframe needs this many fixed markers in view, and
  // the prior's standard deviations are these per marker seen (divided by sqrt(count)).
  int min_prior_markers = 1;
  double prior_position_sigma_m = 0.05;
  double prior_rotation_sigma_rad = 0.02;
  // Priors farther than this many marker sides from their nearest marker are left out (> 0).
  double max_prior_distance_sides = 0.0;
  // true: a prior's covariance is its corners' own (MarkerLocationInformation: it grows with
  // the distance, the view angle and fewer markers) plus the sigmas above as a floor.
  bool prior_from_corners = false;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("corner_sigma_px", corner_sigma_px, 0.0);
    check.Above("marker_huber_delta", marker_huber_delta, 0.0);
    check.Above("marker_chi_square_threshold", marker_chi_square_threshold, 0.0);
    check.AtLeast("min_prior_markers", min_prior_markers, 1);
    check.Above("prior_position_sigma_m", prior_position_sigma_m, 0.0);
    check.Above("prior_rotation_sigma_rad", prior_rotation_sigma_rad, 0.0);
    check.AtLeast("max_prior_distance_sides", max_prior_distance_sides, 0.0);
    return check.ok();
  }
};

// The markers and corner observations to add to one keypoint problem. Collect it under the
// map's lock (it reads keyframe cameras), solve without it.
struct MarkerFactors {
  std::vector<MarkerBundleAdjustmentProblem::Marker> markers;
  std::vector<MarkerBundleAdjustmentProblem::CornerObservation> observations;
  std::vector<MarkerId> marker_ids;  // per entry of `markers`
  int num_fixed_markers = 0;         // fixed markers with at least one observation
  // Soft priors on camera centres of the problem's poses, solved with the markers (or
  // alone: a problem with priors and no marker is still a joint solve).
  std::vector<PositionPrior> position_priors;

  bool empty() const { return observations.empty() && position_priors.empty(); }
};

// Every landmark seen by a keyframe of `keyframe_ids` (problem pose i is keyframe_ids[i]),
// with those observations (corners undistorted with the keyframe's camera). Keyframes that
// are not in `data` are skipped.
MarkerFactors CollectMarkerFactors(const MapData& data, const std::vector<KeyframeId>& keyframe_ids,
                                   const MarkerLandmarks& landmarks,
                                   const MarkerFactorOptions& options = {});

// Solves `problem` with the marker factors (their marker poses updated in place when not
// fixed). The summary is the keypoint side's: `outliers` per keypoint observation;
// `marker_outliers` (when not null) gets one flag per factor observation. Without factors
// this is SolveBundleAdjustment.
BundleAdjustmentSummary SolveBundleAdjustmentWithMarkers(const BundleAdjustmentOptions& solver,
                                                         const MarkerFactorOptions& options,
                                                         MarkerFactors* factors,
                                                         BundleAdjustmentProblem* problem,
                                                         std::vector<bool>* marker_outliers = nullptr);

// The position part of `priors` for the problem poses whose keyframes they name (pose i is
// keyframe_ids[i]): centre from world_from_cam, sigma from the information's first entry.
std::vector<PositionPrior> PositionPriorsOf(const std::vector<KeyframePosePrior>& priors,
                                            const std::vector<KeyframeId>& keyframe_ids);

// Writes the solved poses of non-fixed markers back into `landmarks`; returns how many.
int ApplyMarkerFactors(const MarkerFactors& factors, MarkerLandmarks* landmarks);

// Information of a marker pose prior over [centre, metres; rotation, radians] of `num_markers`
// markers: the options' sigmas divided by sqrt(num_markers); with prior_from_corners, the
// covariance of `corner_information` (MarkerLocationInformation of their corners) plus that.
Matrix6d MarkerPriorInformation(const MarkerFactorOptions& options, double num_markers,
                                const Matrix6d& corner_information);

// Absolute pose priors for a pose graph (node i is keyframe_ids[i]): for each keyframe that
// sees at least min_prior_markers fixed markers, its pose from those markers' corners alone
// (refined from the keyframe's current pose), when the corners fit within the chi-square test.
std::vector<PoseGraphProblem::PosePrior> MarkerPosePriors(const MapData& data,
                                                          const std::vector<KeyframeId>& keyframe_ids,
                                                          const MarkerLandmarks& landmarks,
                                                          const MarkerFactorOptions& options = {});

}  // namespace arucoslam
