// KeyframeDatabase: the place database of a map's keyframes, binding a Vocabulary (BoW vector
// and direct index of each keyframe) to TypedPlaceDatabase<KeyframeId> for place queries.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "arucoslam/feature/place_database.h"
#include "arucoslam/feature/vocabulary.h"
#include "arucoslam/map/covisibility_graph.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/ids.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

// BoW vector and direct index of one image.
struct ImageWords {
  BowVector bow;
  FeatureVector direct;
};

struct KeyframeDatabaseOptions {
  // Depth of the direct index's nodes (1 .. vocabulary levels; clamped to the levels): the
  // coarser, the more candidate pairs per node. Default 2: 100 nodes of a k=10 vocabulary.
  int direct_index_depth = 2;
  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("direct_index_depth", direct_index_depth, 1);
    return check.ok();
  }
};

// Not thread-safe: the owner serialises calls. The vocabulary must outlive the database.
class KeyframeDatabase {
 public:
  explicit KeyframeDatabase(const Vocabulary& vocabulary,
                            const KeyframeDatabaseOptions& options = {});

  // BoW vector and direct index of an image's descriptors (n x 32 CV_8U).
  ImageWords Transform(const cv::Mat& descriptors) const;
  // Stores (or replaces) a keyframe's words.
  void Add(const Keyframe& keyframe);
  void Add(KeyframeId id, ImageWords words);
  bool Erase(KeyframeId id);

  // Stored keyframes sharing words with `bow`, best first (see PlaceDatabase::Query).
  std::vector<TypedPlaceDatabase<KeyframeId>::Match> Query(
      const BowVector& bow, const PlaceQueryOptions& options = {},
      const std::function<bool(KeyframeId)>& keep = {}) const {
    return database_.Query(bow, options, keep);
  }
  // Stored BoW vector / direct index of a keyframe, or nullptr.
  const BowVector* Bow(KeyframeId id) const { return database_.Bow(id); }
  const FeatureVector* Direct(KeyframeId id) const { return database_.Direct(id); }
  bool Contains(KeyframeId id) const { return database_.Bow(id) != nullptr; }
  std::size_t size() const { return database_.size(); }
  const Vocabulary& vocabulary() const { return vocabulary_; }
  int direct_index_depth() const { return depth_; }

 private:
  const Vocabulary& vocabulary_;
  int depth_ = 2;
  TypedPlaceDatabase<KeyframeId> database_;
};

struct CandidateGroupingOptions {
  // Matches sharing fewer words than this fraction of the best match's shared words are
  // dropped ((0, 1]).
  double min_shared_words_ratio = 0.8;
  // A match's group: itself and its `group_size` best covisible keyframes (those that are
  // matches too); the group scores the sum of their scores.
  int group_size = 10;
  // Groups scoring below this fraction of the best group are dropped ((0, 1]).
  double min_group_score_ratio = 0.75;
  int max_candidates = 10;  // at most this many candidates are returned (>= 1)
  bool Check(std::string* why = nullptr) const;
};

struct PlaceCandidate {
  KeyframeId keyframe;       // the best-scoring member of its group
  double score = 0.0;        // its own score
  double group_score = 0.0;  // accumulated over its group
};

// Candidate places from database matches, accumulating scores over covisibility groups so
// that a place seen by several keyframes beats a single lucky one; best group first (ties:
// lower id), one entry per keyframe.
std::vector<PlaceCandidate> GroupCandidates(
    const std::vector<TypedPlaceDatabase<KeyframeId>::Match>& matches,
    const CovisibilityGraph& covisibility, const CandidateGroupingOptions& options = {});

}  // namespace arucoslam
