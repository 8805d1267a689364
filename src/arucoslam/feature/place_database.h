// PlaceDatabase: the inverted index (word -> entries with their weights) over the BoW vectors
// of keyframes, answering "which stored places look like this image?" with L1 scores.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <vector>

#include "arucoslam/feature/bow_vector.h"

namespace arucoslam {

struct PlaceMatch {
  std::uint64_t entry = 0;   // the id given to Add()
  double score = 0.0;        // L1Score of the query and the entry, (0, 1]
  int num_shared_words = 0;  // words present in both
};

struct PlaceQueryOptions {
  int max_results = 10;      // at most this many matches, best first (>= 1)
  double min_score = 0.0;    // matches scoring below this are dropped ([0, 1])
  int min_shared_words = 1;  // matches sharing fewer words are dropped (>= 1)
  bool Check(std::string* why = nullptr) const;
};

// Entries are identified by a 64-bit id (a keyframe id's value; see TypedPlaceDatabase). Not
// thread-safe: the owner serialises calls.
class PlaceDatabase {
 public:
  // `num_words` of the vocabulary the vectors come from (a size hint; the index grows when
  // a larger word id arrives).
  explicit PlaceDatabase(std::size_t num_words = 0);

  // Stores `bow` (L1-normalised, from Vocabulary::Transform) and its direct index under
  // `entry`, replacing an earlier one with the same id.
  void Add(std::uint64_t entry, const BowVector& bow, FeatureVector direct = {});
  // Removes an entry; false when it was not stored.
  bool Erase(std::uint64_t entry);
  void Clear();

  // Stored entries sharing a word with `bow`, scored with L1Score, best first (ties: lower
  // id first). `keep` (optional) filters entries, e.g. to skip the query's own neighbours.
  std::vector<PlaceMatch> Query(const BowVector& bow, const PlaceQueryOptions& options = {},
                                const std::function<bool(std::uint64_t)>& keep = {}) const;

  bool Contains(std::uint64_t entry) const { return entries_.count(entry) > 0; }
  std::size_t size() const { return entries_.size(); }
  std::size_t num_words() const { return inverted_.size(); }
  // The stored vectors of an entry, or nullptr.
  const BowVector* Bow(std::uint64_t entry) const;
  const FeatureVector* Direct(std::uint64_t entry) const;
  // The inverted list of a word: entries holding it, with their weights.
  struct Posting {
    std::uint64_t entry = 0;
    std::uint32_t slot = 0;  // internal: where the entry's score accumulates in a query
    double weight = 0.0;
  };
  // (empty for a word no entry holds).
  const std::vector<Posting>& Postings(WordId word) const;

 private:
  struct Stored {
    BowVector bow;
    FeatureVector direct;
    std::uint32_t slot = 0;
  };
  std::vector<std::vector<Posting>> inverted_;
  std::unordered_map<std::uint64_t, Stored> entries_;
  // Slots give each stored entry a small dense index for the score accumulator.
  std::uint32_t num_slots_ = 0;
  std::vector<std::uint32_t> free_slots_;
};

// PlaceDatabase keyed by a typed id (e.g. KeyframeId from map/ids.h) instead of a raw value.
template <typename Id>
class TypedPlaceDatabase {
 public:
  struct Match {
    Id id;
    double score = 0.0;
    int num_shared_words = 0;
  };
  explicit TypedPlaceDatabase(std::size_t num_words = 0) : database_(num_words) {}
  void Add(Id id, const BowVector& bow, FeatureVector direct = {}) {
    database_.Add(static_cast<std::uint64_t>(id.value), bow, std::move(direct));
  }
  bool Erase(Id id) { return database_.Erase(static_cast<std::uint64_t>(id.value)); }
  std::vector<Match> Query(const BowVector& bow, const PlaceQueryOptions& options = {},
                           const std::function<bool(Id)>& keep = {}) const {
    std::function<bool(std::uint64_t)> keep_raw;
    if (keep) {
      keep_raw = [&keep](std::uint64_t value) {
        return keep(Id(static_cast<typename Id::ValueType>(value)));
      };
    }
    std::vector<Match> matches;
    for (const PlaceMatch& m : database_.Query(bow, options, keep_raw)) {
      matches.push_back(
          {Id(static_cast<typename Id::ValueType>(m.entry)), m.score, m.num_shared_words});
    }
    return matches;
  }
  const FeatureVector* Direct(Id id) const {
    return database_.Direct(static_cast<std::uint64_t>(id.value));
  }
  const BowVector* Bow(Id id) const { return database_.Bow(static_cast<std::uint64_t>(id.value)); }
  std::size_t size() const { return database_.size(); }
  const PlaceDatabase& raw() const { return database_; }

 private:
  PlaceDatabase database_;
};

}  // namespace arucoslam
