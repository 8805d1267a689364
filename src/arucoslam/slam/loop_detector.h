// LoopDetector: proposes loop candidates for a new keyframe, from the place database (score
// relative to its neighbours, consistency over consecutive keyframes) and from shared markers.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "arucoslam/map/map.h"
#include "arucoslam/slam/keyframe_database.h"

namespace arucoslam {

struct LoopDetectorOptions {
  // No detection while the map holds fewer keyframes than this.
  int min_keyframes_in_map = 10;
  // Keyframes sharing at least this many map points with the current one are its
  // neighbourhood: never loop candidates (the map already connects them).
  int exclude_min_weight = 1;
  // Reference score: the lowest BoW score of the current keyframe against its neighbours
  // sharing at least this many points (the best neighbour when none does). Also the weight
  // that makes a keyframe part of a candidate's group in the consistency check.
  int reference_min_weight = 15;
  // Database matches must score at least this fraction of the reference score.
  double min_score_ratio = 1.0;
  int max_query_results = 50;  // raw database matches considered (best first)
  CandidateGroupingOptions grouping;
  // A candidate is returned once its group (it and its covisible keyframes) has been a
  // candidate group for this many consecutive keyframes, the current one included.
  int min_consistent_keyframes = 3;
  // Marker candidates: at most this many, those sharing most markers first.
  int max_marker_candidates = 3;

  bool Check(std::string* why = nullptr) const;
};

// Keyframes that saw a marker (any order); empty for an unknown marker.
using MarkerKeyframeLookup = std::function<std::vector<KeyframeId>(MarkerId)>;

// Marker id -> keyframes whose stored observations include it (ascending ids).
std::map<MarkerId, std::vector<KeyframeId>> BuildMarkerKeyframeIndex(const MapData& data);

struct LoopDetectionStats {
  double reference_score = 0.0;
  int num_database_matches = 0;  // above the score threshold, outside the neighbourhood
  int num_candidate_groups = 0;  // after covisibility grouping
};

struct LoopCandidates {
  std::vector<KeyframeId> by_words;    // consistent BoW candidates, best group first
  std::vector<KeyframeId> by_markers;  // older keyframes sharing a marker, most shared first
  bool empty() const { return by_words.empty() && by_markers.empty(); }
};

// Synchronous; call Detect once per new keyframe, in insertion order (the consistency
// check remembers the previous keyframes' candidate groups). The database must hold the
// map's keyframes; whether the current one is already in it does not matter.
class LoopDetector {
 public:
  LoopDetector(const Map& map, const KeyframeDatabase& database,
               const LoopDetectorOptions& options = {});

  // Place-database candidates of `current` that passed the consistency check.
  std::vector<KeyframeId> DetectByWords(KeyframeId current, LoopDetectionStats* stats = nullptr);
  // Keyframes outside the neighbourhood of `current`, older than it, that saw one of its
  // markers according to `lookup`. Stateless.
  std::vector<KeyframeId> DetectByMarkers(KeyframeId current,
                                          const MarkerKeyframeLookup& lookup) const;
  // Both; markers are looked up in the keyframes' stored observations when `lookup` is empty.
  LoopCandidates Detect(KeyframeId current, const MarkerKeyframeLookup& lookup = {},
                        LoopDetectionStats* stats = nullptr);

  // Forgets the consistency history (e.g. after a loop was closed).
  void Reset() { groups_.clear(); }

 private:
  struct ConsistentGroup {
    std::set<KeyframeId> members;
    int count = 0;  // consecutive keyframes it was a candidate group for
  };
  std::vector<KeyframeId> CheckConsistency(const MapData& data,
                                           const std::vector<PlaceCandidate>& candidates);

  const Map& map_;
  const KeyframeDatabase& database_;
  LoopDetectorOptions options_;
  std::vector<ConsistentGroup> groups_;
};

}  // namespace arucoslam
