// Relocalizer: finds the pose of a frame when tracking is lost: place-database candidates,
// BoW-guided matching, PnP with RANSAC, pose optimisation and guided search by projection.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/optim/pose_optimizer.h"
#include "arucoslam/slam/keyframe_database.h"

namespace arucoslam {

struct RelocalizerOptions {
  // Database query: raw matches considered (best first) before grouping.
  int max_query_results = 50;
  // Grouping of the matches by covisibility into candidate keyframes (best group first).
  CandidateGroupingOptions grouping;
  // BoW-guided matching of the candidate's map points (bits; best < ratio x second best).
  int max_bow_distance = 50;
  double bow_ratio = 0.75;
  bool check_rotation = true;
  int min_bow_matches = 15;
  // PnP with RANSAC: reprojection threshold (pixels, converted to normalised coordinates
  // with fx), iterations, confidence, and inliers needed to go on.
  double pnp_threshold_px = 4.0;
  int pnp_iterations = 300;
  double pnp_confidence = 0.99;
  int min_pnp_inliers = 10;
  PoseOptimizationOptions pose;
  // Guided search by projection of the candidate's points and those of its
  // `projection_neighbours` best covisible keyframes: a wide pass, then a narrow one when
  // the inliers fall short (radius base x scale(level), pixels).
  int projection_neighbours = 5;
  ProjectionMatchOptions wide_search{10.0, 1, 100, 0.9, false, {}};
  ProjectionMatchOptions narrow_search{3.0, 1, 64, 0.9, false, {}};
  // The frame is relocalised with at least this many inliers after the last optimisation.
  int min_inliers = 50;

  bool Check(std::string* why = nullptr) const;
};

struct RelocalizationResult {
  Rigid3 cam_from_world;
  KeyframeId keyframe;  // the candidate the pose came from: the new reference keyframe
  // One entry per keypoint of the frame: the inlier map point, or an invalid id.
  std::vector<MapPointId> map_point_ids;
  int num_inliers = 0;
};

// What one call did, for logs and tests.
struct RelocalizationStats {
  int num_database_matches = 0;
  int num_candidates = 0;  // keyframes verified
  int best_bow_matches = 0;
  int best_pnp_inliers = 0;
  int best_inliers = 0;  // after the last pose optimisation of any candidate
};

// Reads the map (shared lock, briefly per candidate); the database must hold the map's
// keyframes. Synchronous; one call per lost frame.
class Relocalizer {
 public:
  Relocalizer(const Map& map, const KeyframeDatabase& database,
              const RelocalizerOptions& options = {});

  // `frame` needs features with `undistorted` filled and its camera. nullopt when no
  // candidate reaches min_inliers.
  std::optional<RelocalizationResult> Relocalize(const Frame& frame,
                                                 RelocalizationStats* stats = nullptr) const;

  // The same with candidate keyframes found another way (shared marker ids), verified in
  // turn; a candidate the database does not hold yet is matched with its own words.
  std::optional<RelocalizationResult> RelocalizeAt(const Frame& frame,
                                                   const std::vector<KeyframeId>& candidates,
                                                   RelocalizationStats* stats = nullptr) const;

  // The candidate keyframes for a BoW vector, best group first (exposed for tests).
  std::vector<KeyframeId> Candidates(const BowVector& bow, int* num_matches = nullptr) const;

 private:
  // Resets `stats`; the frame's words, or nullopt when its features are missing or lack
  // undistorted positions.
  std::optional<ImageWords> QueryWords(const Frame& frame, RelocalizationStats* stats) const;
  // `keyframe_direct`: the candidate's words when the database does not hold them.
  std::optional<RelocalizationResult> Verify(const Frame& frame, const FeatureVector& direct,
                                             KeyframeId candidate, RelocalizationStats* stats,
                                             const FeatureVector* keyframe_direct = nullptr) const;

  const Map& map_;
  const KeyframeDatabase& database_;
  RelocalizerOptions options_;
};

}  // namespace arucoslam
