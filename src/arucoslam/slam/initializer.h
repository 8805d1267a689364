// Initializer: builds the first map from two frames of a monocular camera. Homography and
// fundamental models are estimated in parallel, one is chosen, its motions are tested by
// triangulation; the result is a value: a motion + points (median depth 1) or a reason.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "arucoslam/feature/keypoints.h"
#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

struct InitializerOptions {
  int min_matches = 100;           // fewer window matches -> kTooFewMatches
  WindowMatchOptions matching;     // window search from frame 1 into frame 2
  int ransac_iterations = 200;     // per model
  double sigma_px = 1.0;           // std of a transfer residual, pixels
  std::uint32_t seed = 0x1217;     // RANSAC seed (deterministic results)
  double homography_share = 0.40;  // choose H when S_H / (S_H + S_F) exceeds this
  // Median keypoint displacement (pixels) below which the camera is taken as static.
  double min_median_flow_px = 2.0;
  // Median displacement left after removing the best rotation (pixels) below which the
  // motion is taken as a pure rotation.
  double min_translation_flow_px = 2.0;
  // Parallax (degrees) that the min_triangulated-th widest consistent point must reach.
  double min_parallax_deg = 1.0;
  double max_reprojection_px = 2.0;        // per view, for a triangulated point to count
  int min_triangulated = 50;               // absolute minimum of good points
  double min_triangulated_fraction = 0.9;  // of the chosen model's inliers
  // A start facing depth (a vehicle leaving from rest down an aisle) keeps its far points below
  // the parallax that triangulates them, and the 90% share above can take seconds to reach.
  // After this many seconds on one reference (MapInitializer), an unambiguous motion needs
  // only relaxed_triangulated_fraction of good points.
  double relax_after_s = 2.5;
  double relaxed_triangulated_fraction = 0.8;
  // kAmbiguous when the second-best motion is consistent with more than this fraction of
  // the points the best explains. With F the wrong motions explain almost nothing; with H the
  // second physical solution of the plane typically keeps 70-80% of the points in front of
  // both cameras, so 0.8 asks that at least a fifth of the points rule it out.
  double ambiguity_ratio = 0.8;
  // Candidate motions whose epipolar support (matches within the Sampson gate of the refined
  // motion) is below this fraction of the best candidate's are not considered. Those above it
  // must share the best one's translation axis (|cos| of the angle at least
  // min_axis_agreement_cos, about 30 degrees), else the pair is ambiguous.
  double min_epipolar_support_ratio = 0.9;
  double min_axis_agreement_cos = 0.866;

  bool Check(std::string* why = nullptr) const;
};

enum class InitFailure {
  kNone,
  kTooFewMatches,       // not enough correspondences between the frames
  kTooLittleParallax,   // camera static or baseline too short for the scene depth
  kPureRotation,        // the images differ by a rotation only
  kAmbiguous,           // two motions explain the matches about equally well
  kTooFewTriangulated,  // the best motion leaves too few good 3D points
};

std::string InitFailureName(InitFailure failure);

enum class TwoViewModelKind { kNone, kHomography, kFundamental };

struct InitializationResult {
  bool success = false;
  InitFailure failure = InitFailure::kNone;
  std::string message;  // one line for logs: what was measured and why it failed
  TwoViewModelKind model = TwoViewModelKind::kNone;
  double homography_share = 0.0;  // S_H / (S_H + S_F)
  int num_matches = 0;            // window matches before any model
  double median_flow_px = 0.0;    // median keypoint displacement of those matches
  double median_parallax_deg = 0.0;
  // Success only: motion of the second camera, scaled so that the median depth of the
  // points in camera 1 is 1; the matches that were triangulated (index1 in frame 1, index2
  // in frame 2) and their points in camera 1, one per match.
  Rigid3 cam2_from_cam1;
  std::vector<FeatureMatch> matches;
  std::vector<Eigen::Vector3d> points_in_cam1;
};

// Rescales a two-view result (motion and points together) so that the median depth of its
// points in camera 1 is 1, the gauge of every monocular initial map. No points: unchanged.
void ScaleToUnitMedianDepth(InitializationResult* result);

class Initializer {
 public:
  explicit Initializer(const InitializerOptions& options = {});

  // Matches `frame2` against `frame1` in a window and initialises from the matches. Both
  // must have `undistorted` filled (UndistortFeatures) for `camera`.
  InitializationResult Initialize(const OrbFeatures& frame1, const OrbFeatures& frame2,
                                  const CameraModel& camera) const;

  // From given correspondences of undistorted normalised coordinates; `matches` index into
  // `normalised1` / `normalised2`. Only the camera's focal lengths and centre are used.
  InitializationResult InitializeFromMatches(const std::vector<Eigen::Vector2d>& normalised1,
                                             const std::vector<Eigen::Vector2d>& normalised2,
                                             const std::vector<FeatureMatch>& matches,
                                             const CameraModel& camera) const;

  const InitializerOptions& options() const { return options_; }

 private:
  InitializerOptions options_;
};

}  // namespace arucoslam
