#include "arucoslam/feature/orb_matcher.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// Best and second-best distances of one descriptor against a set of candidates.
struct BestTwo {
  int best_index = -1;
  int best = std::numeric_limits<int>::max();
  int second = std::numeric_limits<int>::max();
  void Add(int index, int distance) {
    if (distance < best) {
      second = best;
      best = distance;
      best_index = index;
    } else if (distance < second) {
      second = distance;
    }
  }
  bool Passes(int max_distance, double ratio) const {
    if (best_index < 0 || best > max_distance) return false;
    return ratio >= 1.0 || second == std::numeric_limits<int>::max() ||
           static_cast<double>(best) < ratio * second;
  }
};

// Each second-set index keeps only its closest match; order by index1 is kept.
std::vector<FeatureMatch> KeepBestPerTarget(const std::vector<FeatureMatch>& matches) {
  int max_index2 = -1;
  for (const FeatureMatch& m : matches) max_index2 = std::max(max_index2, m.index2);
  std::vector<int> owner(max_index2 + 1, -1);
  for (int k = 0; k < static_cast<int>(matches.size()); ++k) {
    int& current = owner[matches[k].index2];
    if (current < 0 || matches[k].distance < matches[current].distance) current = k;
  }
  std::vector<FeatureMatch> kept;
  for (int k = 0; k < static_cast<int>(matches.size()); ++k) {
    if (owner[matches[k].index2] == k) kept.push_back(matches[k]);
  }
  return kept;
}

std::vector<float> Angles(const OrbFeatures& features) {
  std::vector<float> angles;
  angles.reserve(features.keypoints.size());
  for (const cv::KeyPoint& kp : features.keypoints) angles.push_back(kp.angle);
  return angles;
}

}  // namespace

// Two builds of the count, chosen when the program loads: the popcnt instruction where the
// CPU has one, else the compiler's portable count. Not in sanitizer builds: the loader picks
// the build before the sanitizer's runtime is up, and ThreadSanitizer crashes there.
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__) && \
    !defined(__SANITIZE_THREAD__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("popcnt", "default")))
#endif
int HammingDistance(const std::uint8_t* a, const std::uint8_t* b) {
  int bits = 0;
  for (int k = 0; k < kOrbDescriptorBytes; k += 8) {
    std::uint64_t wa, wb;
    std::memcpy(&wa, a + k, 8);
    std::memcpy(&wb, b + k, 8);
    bits += __builtin_popcountll(wa ^ wb);
  }
  return bits;
}

bool RotationCheckOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("histogram_bins", histogram_bins, 1);
  check.AtLeast("keep_bins", keep_bins, 1);
  check.InRange("min_fraction_of_best", min_fraction_of_best, 0.0, 1.0, Interval::kClosed);
  return check.ok();
}

std::vector<FeatureMatch> FilterByRotationConsistency(const std::vector<FeatureMatch>& matches,
                                                      const std::vector<float>& angles1,
                                                      const std::vector<float>& angles2,
                                                      const RotationCheckOptions& options) {
  const int bins = options.histogram_bins;
  std::vector<int> bin_of(matches.size());
  std::vector<int> counts(bins, 0);
  for (std::size_t k = 0; k < matches.size(); ++k) {
    double diff = angles2[matches[k].index2] - angles1[matches[k].index1];
    diff = std::fmod(diff, 360.0);
    if (diff < 0.0) diff += 360.0;
    bin_of[k] = std::min(bins - 1, static_cast<int>(diff * bins / 360.0));
    ++counts[bin_of[k]];
  }
  std::vector<int> order(bins);
  for (int b = 0; b < bins; ++b) order[b] = b;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return counts[a] > counts[b]; });
  std::vector<bool> keep_bin(bins, false);
  for (int r = 0; r < std::min(options.keep_bins, bins); ++r) {
    const int b = order[r];
    if (counts[b] == 0) break;
    if (r > 0 && counts[b] < options.min_fraction_of_best * counts[order[0]]) break;
    keep_bin[b] = true;
  }
  std::vector<FeatureMatch> kept;
  for (std::size_t k = 0; k < matches.size(); ++k) {
    if (keep_bin[bin_of[k]]) kept.push_back(matches[k]);
  }
  return kept;
}

bool BruteForceMatchOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("max_distance", max_distance, 0);
  check.Above("ratio", ratio, 0.0);
  check.Nested("rotation", rotation);
  return check.ok();
}

std::vector<FeatureMatch> MatchBruteForce(const OrbFeatures& features1,
                                          const OrbFeatures& features2,
                                          const BruteForceMatchOptions& options) {
  if (!options.Check()) throw std::invalid_argument("BruteForceMatchOptions: invalid values");
  const int n1 = static_cast<int>(features1.size()), n2 = static_cast<int>(features2.size());
  std::vector<BestTwo> forward(n1);
  std::vector<int> backward_best(n2, std::numeric_limits<int>::max());
  std::vector<int> backward_index(n2, -1);
  for (int i = 0; i < n1; ++i) {
    const std::uint8_t* d1 = features1.Descriptor(i);
    for (int j = 0; j < n2; ++j) {
      const int distance = HammingDistance(d1, features2.Descriptor(j));
      forward[i].Add(j, distance);
      if (distance < backward_best[j]) {
        backward_best[j] = distance;
        backward_index[j] = i;
      }
    }
  }
  std::vector<FeatureMatch> matches;
  for (int i = 0; i < n1; ++i) {
    if (!forward[i].Passes(options.max_distance, options.ratio)) continue;
    const int j = forward[i].best_index;
    if (options.cross_check && backward_index[j] != i) continue;
    matches.push_back({i, j, forward[i].best});
  }
  matches = KeepBestPerTarget(matches);
  if (options.check_rotation) {
    matches = FilterByRotationConsistency(matches, Angles(features1), Angles(features2),
                                          options.rotation);
  }
  return matches;
}

bool WindowMatchOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("window_radius_px", window_radius_px, 0.0);
  check.AtLeast("max_level_difference", max_level_difference, 0);
  check.AtLeast("max_distance", max_distance, 0);
  check.Above("ratio", ratio, 0.0);
  check.Nested("rotation", rotation);
  return check.ok();
}

std::vector<FeatureMatch> MatchInWindow(const OrbFeatures& features1, const OrbFeatures& features2,
                                        const FeatureGrid& grid2,
                                        const std::vector<Eigen::Vector2d>& predicted_in_2,
                                        const WindowMatchOptions& options) {
  if (!options.Check()) throw std::invalid_argument("WindowMatchOptions: invalid values");
  if (predicted_in_2.size() != features1.size()) {
    throw std::invalid_argument("MatchInWindow: one predicted position per feature expected");
  }
  std::vector<FeatureMatch> matches;
  for (int i = 0; i < static_cast<int>(features1.size()); ++i) {
    const int level = features1.keypoints[i].octave;
    const std::vector<int> candidates = grid2.FeaturesInRadius(
        predicted_in_2[i], options.window_radius_px,
        std::max(0, level - options.max_level_difference), level + options.max_level_difference);
    BestTwo best;
    const std::uint8_t* d1 = features1.Descriptor(i);
    for (int j : candidates) best.Add(j, HammingDistance(d1, features2.Descriptor(j)));
    if (best.Passes(options.max_distance, options.ratio)) {
      matches.push_back({i, best.best_index, best.best});
    }
  }
  matches = KeepBestPerTarget(matches);
  if (options.check_rotation) {
    matches = FilterByRotationConsistency(matches, Angles(features1), Angles(features2),
                                          options.rotation);
  }
  return matches;
}

bool ProjectionMatchOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("base_radius_px", base_radius_px, 0.0);
  check.AtLeast("level_tolerance", level_tolerance, 0);
  check.AtLeast("max_distance", max_distance, 0);
  check.Above("ratio", ratio, 0.0);
  check.Nested("rotation", rotation);
  return check.ok();
}

std::vector<FeatureMatch> MatchByProjection(const OrbFeatures& features, const FeatureGrid& grid,
                                            const std::vector<ProjectionQuery>& queries,
                                            const std::vector<bool>& taken,
                                            const ProjectionMatchOptions& options) {
  if (!options.Check()) throw std::invalid_argument("ProjectionMatchOptions: invalid values");
  const int top_level = features.pyramid.num_levels - 1;
  std::vector<FeatureMatch> matches;
  for (int q = 0; q < static_cast<int>(queries.size()); ++q) {
    const ProjectionQuery& query = queries[q];
    if (query.descriptor == nullptr) continue;
    const int level = std::clamp(query.predicted_level, 0, std::max(0, top_level));
    const double scale = features.pyramid.scales.empty() ? 1.0 : features.pyramid.scales[level];
    const double radius = options.base_radius_px * query.radius_factor * scale;
    const std::vector<int> candidates =
        grid.FeaturesInRadius(query.pixel, radius, std::max(0, level - options.level_tolerance),
                              level + options.level_tolerance);
    int best = std::numeric_limits<int>::max(), second = best, best_index = -1;
    int best_level = -1, second_level = -1;
    for (int j : candidates) {
      if (!taken.empty() && taken[j]) continue;
      const int distance = HammingDistance(query.descriptor, features.Descriptor(j));
      if (distance < best) {
        second = best;
        second_level = best_level;
        best = distance;
        best_index = j;
        best_level = features.keypoints[j].octave;
      } else if (distance < second) {
        second = distance;
        second_level = features.keypoints[j].octave;
      }
    }
    if (best_index < 0 || best > options.max_distance) continue;
    // The ratio test only between candidates at the same level (a repeated texture at
    // another scale is not an ambiguity for the predicted scale).
    if (best_level == second_level && options.ratio < 1.0 && best >= options.ratio * second) {
      continue;
    }
    matches.push_back({q, best_index, best});
  }
  matches = KeepBestPerTarget(matches);
  if (options.check_rotation) {
    std::vector<float> query_angles;
    query_angles.reserve(queries.size());
    for (const ProjectionQuery& query : queries) query_angles.push_back(query.angle);
    matches =
        FilterByRotationConsistency(matches, query_angles, Angles(features), options.rotation);
  }
  return matches;
}

}  // namespace arucoslam
