// Descriptor matching for ORB features: Hamming distance, brute force with a ratio test,
// window search for initialisation, search by projection with scale-aware radii, and the
// rotation-consistency filter that drops matches disagreeing with the dominant rotation.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "arucoslam/feature/feature_grid.h"
#include "arucoslam/feature/keypoints.h"

namespace arucoslam {

struct FeatureMatch {
  int index1 = -1;   // feature (or query) index in the first set
  int index2 = -1;   // feature index in the second set
  int distance = 0;  // Hamming distance of the descriptors, bits
};

// Bits that differ between two 32-byte descriptors (0..256).
int HammingDistance(const std::uint8_t* a, const std::uint8_t* b);

struct RotationCheckOptions {
  int histogram_bins = 30;  // bins over 360 degrees of keypoint-angle difference
  int keep_bins = 3;        // the most populated bins that are kept
  // A kept bin other than the fullest must hold at least this fraction of the fullest.
  double min_fraction_of_best = 0.1;
  bool Check(std::string* why = nullptr) const;
};

// Keeps the matches whose angle difference (angle2 - angle1) falls in the dominant bins.
// `angles1[m.index1]` and `angles2[m.index2]` are in degrees; order of matches is kept.
std::vector<FeatureMatch> FilterByRotationConsistency(const std::vector<FeatureMatch>& matches,
                                                      const std::vector<float>& angles1,
                                                      const std::vector<float>& angles2,
                                                      const RotationCheckOptions& options = {});

struct BruteForceMatchOptions {
  int max_distance = 64;       // bits; a best match farther than this is dropped
  double ratio = 0.8;          // best must be < ratio * second best (1 disables)
  bool cross_check = true;     // keep only mutual best matches
  bool check_rotation = true;  // apply FilterByRotationConsistency
  RotationCheckOptions rotation;
  bool Check(std::string* why = nullptr) const;
};

std::vector<FeatureMatch> MatchBruteForce(const OrbFeatures& features1,
                                          const OrbFeatures& features2,
                                          const BruteForceMatchOptions& options = {});

struct WindowMatchOptions {
  double window_radius_px = 100.0;  // search radius around the predicted position, pixels
  int max_level_difference = 1;     // |level2 - level1| allowed
  int max_distance = 50;            // bits
  double ratio = 0.9;               // best < ratio * second best
  bool check_rotation = true;
  RotationCheckOptions rotation;
  bool Check(std::string* why = nullptr) const;
};

// Matching for initialisation: feature i of `features1` is searched for in `features2` within
// the window around `predicted_in_2[i]` (level-0 pixels; usually where it was last matched or
// its own position). Each feature of `features2` keeps only its best match.
std::vector<FeatureMatch> MatchInWindow(const OrbFeatures& features1, const OrbFeatures& features2,
                                        const FeatureGrid& grid2,
                                        const std::vector<Eigen::Vector2d>& predicted_in_2,
                                        const WindowMatchOptions& options = {});

// One point projected into an image, to be matched there by descriptor.
struct ProjectionQuery {
  Eigen::Vector2d pixel;                     // predicted position, level-0 pixels
  int predicted_level = 0;                   // predicted pyramid level
  const std::uint8_t* descriptor = nullptr;  // 32 bytes; must stay valid during the call
  double radius_factor = 1.0;                // extra scaling of the search radius (e.g. view angle)
  float angle = -1.0f;                       // keypoint angle it was seen with (deg), < 0 unknown
};

struct ProjectionMatchOptions {
  // Search radius in level-0 pixels = base_radius_px * radius_factor * scale(predicted_level).
  double base_radius_px = 4.0;
  int level_tolerance = 1;      // candidates at levels predicted +- this
  int max_distance = 100;       // bits
  double ratio = 0.8;           // best < ratio * second best when both are at the same level
  bool check_rotation = false;  // needs every query's angle >= 0
  RotationCheckOptions rotation;
  bool Check(std::string* why = nullptr) const;
};

// Returns matches with index1 = query index and index2 = feature index; each feature is used
// at most once (the closer descriptor wins). Features with `taken[i]` true are skipped
// (`taken` may be empty).
std::vector<FeatureMatch> MatchByProjection(const OrbFeatures& features, const FeatureGrid& grid,
                                            const std::vector<ProjectionQuery>& queries,
                                            const std::vector<bool>& taken,
                                            const ProjectionMatchOptions& options = {});

}  // namespace arucoslam
