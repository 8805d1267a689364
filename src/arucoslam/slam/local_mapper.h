// LocalMapper: the local mapping of one new keyframe, synchronously: refresh its points,
// cull bad recent points, triangulate new points with covisible keyframes, fuse duplicates,
// run local bundle adjustment and cull redundant keyframes. pipeline/ runs it on a thread.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "arucoslam/map/map.h"
#include "arucoslam/optim/local_bundle_adjustment.h"

namespace arucoslam {

struct LocalMapperOptions {
  // Triangulation: the new keyframe is paired with up to this many best covisible keyframes.
  int triangulation_neighbours = 10;
  // A pair is skipped when baseline / median scene depth of the neighbour is below this.
  double min_baseline_depth_ratio = 0.01;
  int max_match_distance = 50;   // bits, descriptor distance of a triangulation match
  double match_ratio = 0.8;      // best < ratio * second best among epipolar candidates
  // Epipolar test: squared distance to the epipolar line below chi2(1 dof, 95%) x sigma^2.
  double epipolar_chi2 = 3.841;
  // Candidates closer than this x scale(level) pixels to the epipole are skipped.
  double min_epipole_distance_px = 10.0;
  // Rays must make an angle with cosine below this (0.99999: about 0.26 degrees). A test on
  // the measured parallax keeps, among matches near the threshold, those whose noise widened
  // the angle, so their points lie too near and the map shrinks; the widest-parallax pairing
  // (TriangulateNewPoints) and a low floor shrink it least on the simulated routes
  // (BENCHMARKS.md, "Keypoint-only scale drift"). Bundle adjustment refines the
  // low-parallax points as more keyframes see them.
  double max_parallax_cos = 0.99999;
  // Reprojection test per view: squared error below chi2(2 dof, 95%) x sigma^2.
  double reprojection_chi2 = 5.991;
  // Scale consistency: distance ratio and pyramid scale ratio may differ by this x the
  // pyramid's scale factor.
  double scale_consistency_factor = 1.5;
  // A keypoint matched in several neighbours: its point (from the widest-parallax pair) is
  // kept only when it reprojects within `reprojection_chi2` into every other neighbour's
  // matched keypoint. Pairs that disagree hold a wrong match, and such points lie too near
  // more often than too far.
  bool multi_view_check = true;
  // Fusion: the new keyframe's points are projected into up to this many neighbours (and
  // their points into it) and matched within this radius x scale(level), pixels.
  int fusion_neighbours = 20;
  double fusion_radius_px = 3.0;
  int fusion_max_distance = 50;  // bits
  // Recent point culling: found/visible below this ratio, or fewer than
  // `min_point_observations` observations two keyframes after creation, erases a point.
  double min_found_ratio = 0.25;
  int min_point_observations = 3;
  bool run_bundle_adjustment = true;
  // Local BA with two fixed keyframes: they hold the monocular scale (one leaves it free).
  LocalBundleAdjustmentOptions bundle_adjustment = [] {
    LocalBundleAdjustmentOptions options;
    options.min_fixed_keyframes = 2;
    // A BA asked to yield (SetYieldRequest) still takes 5 iterations: stopping after one
    // left the threaded map too far from converged (BENCHMARKS.md, "Threaded runs").
    options.solver.min_iterations_before_stop = 5;
    return options;
  }();
  // Keyframe culling: a covisible keyframe (not the first) is erased when this fraction of
  // its points are seen, at the same or a finer scale, by at least `redundant_observers`
  // other keyframes.
  double redundant_fraction = 0.9;
  int redundant_observers = 3;
  // An older keyframe (not the first) left with fewer map points than this is erased too:
  // nothing can be tracked from it, and bundle adjustment cannot hold its pose.
  int min_keyframe_points = 15;
  bool cull_keyframes = true;
  // With marker landmarks set: a keyframe is kept while one of the markers it saw is seen
  // by fewer than this many other keyframes (a marker's views hold its pose and the scale).
  int min_marker_keyframes = 3;

  bool Check(std::string* why = nullptr) const;
};

struct LocalMappingResult {
  bool processed = false;  // false when the keyframe no longer exists
  int num_refreshed_points = 0;
  int num_culled_points = 0;
  int num_new_points = 0;
  int num_fused_points = 0;
  int num_culled_keyframes = 0;
  LocalBundleAdjustmentResult bundle_adjustment;
  // Wall time of each step, milliseconds.
  double triangulation_ms = 0.0;
  double fusion_ms = 0.0;
  double bundle_adjustment_ms = 0.0;
  double culling_ms = 0.0;  // points and keyframes
};

class LocalMapper {
 public:
  explicit LocalMapper(Map& map, const LocalMapperOptions& options = {});

  // Runs every step for `keyframe`, which tracking has just inserted into the map.
  LocalMappingResult ProcessKeyframe(KeyframeId keyframe);

  // The steps, public for tests. Each returns how many points or keyframes it changed.
  int RefreshKeyframePoints(KeyframeId keyframe);
  int CullRecentPoints();
  int TriangulateNewPoints(KeyframeId keyframe);
  int FuseDuplicates(KeyframeId keyframe);
  int CullRedundantKeyframes(KeyframeId keyframe);

  const LocalMapperOptions& options() const { return options_; }
  // Markers whose observations join local BA (null: none). Used only inside
  // ProcessKeyframe: the caller may change them between calls, not during one.
  void SetMarkerLandmarks(MarkerLandmarks* markers) { markers_ = markers; }
  // Keyframes for which `keep` returns true are never culled (e.g. those anchoring a pending
  // world alignment). Set before mapping starts; called on the mapping thread.
  void SetKeyframeGuard(std::function<bool(const Keyframe&)> keep) { keep_ = std::move(keep); }
  // Asked after each local BA iteration (from bundle_adjustment.solver.min_iterations_before_stop
  // on): true ends the BA there, with the iterate reached (e.g. while another keyframe waits to
  // be mapped, as ORB-SLAM's abort).
  // Set before mapping starts; called on the mapping thread.
  void SetYieldRequest(std::function<bool()> yield) {
    options_.bundle_adjustment.solver.stop_requested = std::move(yield);
  }

 private:
  Map& map_;
  LocalMapperOptions options_;
  MarkerLandmarks* markers_ = nullptr;
  std::function<bool(const Keyframe&)> keep_;
  int num_processed_ = 0;  // keyframes processed so far
  // Points created here, with the value of num_processed_ when they were made.
  std::vector<std::pair<MapPointId, int>> recent_points_;
};

}  // namespace arucoslam
