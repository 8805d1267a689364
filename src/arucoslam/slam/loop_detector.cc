#include "arucoslam/slam/loop_detector.h"

#include <algorithm>
#include <stdexcept>

#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// The keyframes sharing at least `min_weight` points with `current`.
std::set<KeyframeId> Neighbourhood(const MapData& data, KeyframeId current, int min_weight) {
  std::set<KeyframeId> neighbours;
  if (!data.covisibility().Contains(current)) return neighbours;
  for (const auto& [id, weight] : data.covisibility().Neighbours(current)) {
    if (weight >= min_weight) neighbours.insert(id);
  }
  return neighbours;
}

// Lowest score of `bow` against the strongly covisible neighbours (or the best neighbour).
double ReferenceScore(const MapData& data, const KeyframeDatabase& database, KeyframeId current,
                      const BowVector& bow, int min_weight) {
  std::vector<KeyframeId> neighbours =
      data.covisibility().CovisibleWithMinWeight(current, min_weight);
  if (neighbours.empty()) neighbours = data.covisibility().BestCovisible(current, 1);
  double reference = 1.0;
  bool any = false;
  for (const KeyframeId& neighbour : neighbours) {
    const BowVector* other = database.Bow(neighbour);
    if (other == nullptr) continue;
    reference = std::min(reference, L1Score(bow, *other));
    any = true;
  }
  return any ? reference : 0.0;
}

}  // namespace

bool LoopDetectorOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("min_keyframes_in_map", min_keyframes_in_map, 0);
  check.AtLeast("exclude_min_weight", exclude_min_weight, 1);
  check.AtLeast("reference_min_weight", reference_min_weight, 1);
  check.AtLeast("min_score_ratio", min_score_ratio, 0.0);
  check.AtLeast("max_query_results", max_query_results, 1);
  check.Nested("grouping", grouping);
  check.AtLeast("min_consistent_keyframes", min_consistent_keyframes, 1);
  check.AtLeast("max_marker_candidates", max_marker_candidates, 0);
  return check.ok();
}

std::map<MarkerId, std::vector<KeyframeId>> BuildMarkerKeyframeIndex(const MapData& data) {
  std::map<MarkerId, std::vector<KeyframeId>> index;
  for (const auto& [id, keyframe] : data.keyframes()) {
    for (const MarkerObservation& marker : keyframe.markers) {
      std::vector<KeyframeId>& seen = index[marker.marker_id];
      if (seen.empty() || seen.back() != id) seen.push_back(id);
    }
  }
  return index;
}

LoopDetector::LoopDetector(const Map& map, const KeyframeDatabase& database,
                           const LoopDetectorOptions& options)
    : map_(map), database_(database), options_(options) {
  if (!options.Check()) throw std::invalid_argument("LoopDetectorOptions: bad options");
}

std::vector<KeyframeId> LoopDetector::DetectByWords(KeyframeId current, LoopDetectionStats* stats) {
  LoopDetectionStats local_stats;
  LoopDetectionStats& s = stats != nullptr ? *stats : local_stats;
  s = {};
  return map_.Read([&](const MapData& data) -> std::vector<KeyframeId> {
    const Keyframe* keyframe = data.FindKeyframe(current);
    if (keyframe == nullptr ||
        static_cast<int>(data.NumKeyframes()) < options_.min_keyframes_in_map) {
      groups_.clear();
      return {};
    }
    const BowVector* stored = database_.Bow(current);
    const BowVector bow =
        stored != nullptr ? *stored : database_.Transform(keyframe->features.descriptors).bow;
    s.reference_score =
        ReferenceScore(data, database_, current, bow, options_.reference_min_weight);
    const std::set<KeyframeId> excluded = Neighbourhood(data, current, options_.exclude_min_weight);
    PlaceQueryOptions query;
    query.max_results = options_.max_query_results;
    query.min_score = std::min(1.0, options_.min_score_ratio * s.reference_score);
    const auto matches = database_.Query(bow, query, [&](KeyframeId id) {
      return id != current && excluded.count(id) == 0 && data.FindKeyframe(id) != nullptr;
    });
    s.num_database_matches = static_cast<int>(matches.size());
    const std::vector<PlaceCandidate> candidates =
        GroupCandidates(matches, data.covisibility(), options_.grouping);
    s.num_candidate_groups = static_cast<int>(candidates.size());
    return CheckConsistency(data, candidates);
  });
}

std::vector<KeyframeId> LoopDetector::CheckConsistency(
    const MapData& data, const std::vector<PlaceCandidate>& candidates) {
  std::vector<ConsistentGroup> next;
  std::vector<KeyframeId> accepted;
  for (const PlaceCandidate& candidate : candidates) {
    ConsistentGroup group;
    group.members.insert(candidate.keyframe);
    for (const KeyframeId& id : data.covisibility().CovisibleWithMinWeight(
             candidate.keyframe, options_.reference_min_weight)) {
      group.members.insert(id);
    }
    group.count = 1;
    for (const ConsistentGroup& previous : groups_) {
      const bool shares =
          std::any_of(previous.members.begin(), previous.members.end(),
                      [&](const KeyframeId& id) { return group.members.count(id); });
      if (shares) group.count = std::max(group.count, previous.count + 1);
    }
    if (group.count >= options_.min_consistent_keyframes) accepted.push_back(candidate.keyframe);
    next.push_back(std::move(group));
  }
  groups_ = std::move(next);
  return accepted;
}

std::vector<KeyframeId> LoopDetector::DetectByMarkers(KeyframeId current,
                                                      const MarkerKeyframeLookup& lookup) const {
  std::map<KeyframeId, int> shared;  // candidate -> markers shared with current
  map_.Read([&](const MapData& data) {
    const Keyframe* keyframe = data.FindKeyframe(current);
    if (keyframe == nullptr) return 0;
    const std::set<KeyframeId> excluded = Neighbourhood(data, current, options_.exclude_min_weight);
    std::set<MarkerId> markers;
    for (const MarkerObservation& marker : keyframe->markers) markers.insert(marker.marker_id);
    for (const MarkerId& marker : markers) {
      const std::vector<KeyframeId> seen_by = lookup(marker);
      for (const KeyframeId& id : std::set<KeyframeId>(seen_by.begin(), seen_by.end())) {
        if (id < current && excluded.count(id) == 0 && data.FindKeyframe(id) != nullptr) {
          ++shared[id];
        }
      }
    }
    return 0;
  });
  std::vector<std::pair<int, KeyframeId>> sorted;
  for (const auto& [id, count] : shared) sorted.emplace_back(-count, id);
  std::sort(sorted.begin(), sorted.end());
  std::vector<KeyframeId> candidates;
  for (const auto& entry : sorted) {
    if (static_cast<int>(candidates.size()) >= options_.max_marker_candidates) break;
    candidates.push_back(entry.second);
  }
  return candidates;
}

LoopCandidates LoopDetector::Detect(KeyframeId current, const MarkerKeyframeLookup& lookup,
                                    LoopDetectionStats* stats) {
  LoopCandidates candidates;
  candidates.by_words = DetectByWords(current, stats);
  if (lookup) {
    candidates.by_markers = DetectByMarkers(current, lookup);
  } else {
    const auto index =
        map_.Read([](const MapData& data) { return BuildMarkerKeyframeIndex(data); });
    candidates.by_markers = DetectByMarkers(current, [&index](MarkerId marker) {
      const auto it = index.find(marker);
      return it == index.end() ? std::vector<KeyframeId>() : it->second;
    });
  }
  return candidates;
}

}  // namespace arucoslam
