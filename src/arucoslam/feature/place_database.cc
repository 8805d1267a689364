#include "arucoslam/feature/place_database.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool PlaceQueryOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("max_results", max_results, 1);
  check.InRange("min_score", min_score, 0.0, 1.0, Interval::kClosed);
  check.AtLeast("min_shared_words", min_shared_words, 1);
  return check.ok();
}

PlaceDatabase::PlaceDatabase(std::size_t num_words) : inverted_(num_words) {}

void PlaceDatabase::Add(std::uint64_t entry, const BowVector& bow, FeatureVector direct) {
  Erase(entry);
  std::uint32_t slot = num_slots_;
  if (free_slots_.empty()) {
    ++num_slots_;
  } else {
    slot = free_slots_.back();
    free_slots_.pop_back();
  }
  for (const BowVector::Entry& word : bow.entries) {
    if (word.word >= inverted_.size()) inverted_.resize(word.word + 1);
    inverted_[word.word].push_back({entry, slot, word.weight});
  }
  entries_[entry] = Stored{bow, std::move(direct), slot};
}

bool PlaceDatabase::Erase(std::uint64_t entry) {
  const auto it = entries_.find(entry);
  if (it == entries_.end()) return false;
  for (const BowVector::Entry& word : it->second.bow.entries) {
    std::vector<Posting>& postings = inverted_[word.word];
    std::erase_if(postings, [entry](const Posting& p) { return p.entry == entry; });
  }
  free_slots_.push_back(it->second.slot);
  entries_.erase(it);
  return true;
}

void PlaceDatabase::Clear() {
  for (std::vector<Posting>& postings : inverted_) postings.clear();
  entries_.clear();
  num_slots_ = 0;
  free_slots_.clear();
}

std::vector<PlaceMatch> PlaceDatabase::Query(const BowVector& bow, const PlaceQueryOptions& options,
                                             const std::function<bool(std::uint64_t)>& keep) const {
  if (!options.Check()) throw std::invalid_argument("PlaceDatabase::Query: bad options");
  // Accumulates, per entry, sum over shared words of |q| + |e| - |q - e| (= 2 min(q, e) for
  // non-negative weights): twice the L1 score.
  std::vector<PlaceMatch> accumulated(num_slots_);
  std::vector<std::uint32_t> touched;
  for (const BowVector::Entry& word : bow.entries) {
    if (word.word >= inverted_.size()) continue;
    for (const Posting& posting : inverted_[word.word]) {
      PlaceMatch& match = accumulated[posting.slot];
      if (match.num_shared_words == 0) touched.push_back(posting.slot);
      match.entry = posting.entry;
      match.score +=
          std::abs(word.weight) + std::abs(posting.weight) - std::abs(word.weight - posting.weight);
      ++match.num_shared_words;
    }
  }
  std::vector<PlaceMatch> matches;
  matches.reserve(touched.size());
  for (std::uint32_t slot : touched) {
    PlaceMatch& match = accumulated[slot];
    const std::uint64_t entry = match.entry;
    match.score = std::clamp(0.5 * match.score, 0.0, 1.0);
    if (match.score < options.min_score || match.num_shared_words < options.min_shared_words) {
      continue;
    }
    if (keep && !keep(entry)) continue;
    matches.push_back(match);
  }
  const auto better = [](const PlaceMatch& a, const PlaceMatch& b) {
    return a.score != b.score ? a.score > b.score : a.entry < b.entry;
  };
  const std::size_t count = std::min<std::size_t>(options.max_results, matches.size());
  std::partial_sort(matches.begin(), matches.begin() + count, matches.end(), better);
  matches.resize(count);
  return matches;
}

const BowVector* PlaceDatabase::Bow(std::uint64_t entry) const {
  const auto it = entries_.find(entry);
  return it == entries_.end() ? nullptr : &it->second.bow;
}

const FeatureVector* PlaceDatabase::Direct(std::uint64_t entry) const {
  const auto it = entries_.find(entry);
  return it == entries_.end() ? nullptr : &it->second.direct;
}

const std::vector<PlaceDatabase::Posting>& PlaceDatabase::Postings(WordId word) const {
  static const std::vector<Posting> kNone;
  return word < inverted_.size() ? inverted_[word] : kNone;
}

}  // namespace arucoslam
