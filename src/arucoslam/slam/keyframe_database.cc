#include "arucoslam/slam/keyframe_database.h"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <utility>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

KeyframeDatabase::KeyframeDatabase(const Vocabulary& vocabulary,
                                   const KeyframeDatabaseOptions& options)
    : vocabulary_(vocabulary), database_(vocabulary.num_words()) {
  if (!options.Check()) throw std::invalid_argument("KeyframeDatabaseOptions: bad options");
  if (vocabulary.empty()) throw std::invalid_argument("KeyframeDatabase: empty vocabulary");
  depth_ = std::min(options.direct_index_depth, vocabulary.levels());
}

ImageWords KeyframeDatabase::Transform(const cv::Mat& descriptors) const {
  ImageWords words;
  if (descriptors.empty()) return words;
  vocabulary_.Transform(descriptors, depth_, &words.bow, &words.direct);
  return words;
}

void KeyframeDatabase::Add(const Keyframe& keyframe) {
  Add(keyframe.id, Transform(keyframe.features.descriptors));
}

void KeyframeDatabase::Add(KeyframeId id, ImageWords words) {
  database_.Add(id, words.bow, std::move(words.direct));
}

bool KeyframeDatabase::Erase(KeyframeId id) { return database_.Erase(id); }

bool CandidateGroupingOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.InRange("min_shared_words_ratio", min_shared_words_ratio, 0.0, 1.0, Interval::kOpenClosed);
  check.AtLeast("group_size", group_size, 0);
  check.InRange("min_group_score_ratio", min_group_score_ratio, 0.0, 1.0, Interval::kOpenClosed);
  check.AtLeast("max_candidates", max_candidates, 1);
  return check.ok();
}

std::vector<PlaceCandidate> GroupCandidates(
    const std::vector<TypedPlaceDatabase<KeyframeId>::Match>& matches,
    const CovisibilityGraph& covisibility, const CandidateGroupingOptions& options) {
  int max_shared = 0;
  for (const auto& match : matches) max_shared = std::max(max_shared, match.num_shared_words);
  std::map<KeyframeId, double> scores;
  for (const auto& match : matches) {
    if (match.num_shared_words >= options.min_shared_words_ratio * max_shared) {
      scores[match.id] = match.score;
    }
  }
  std::map<KeyframeId, PlaceCandidate> best_of_group;  // representative -> candidate
  double best_group_score = 0.0;
  for (const auto& [id, score] : scores) {
    PlaceCandidate candidate{id, score, score};
    if (covisibility.Contains(id)) {
      for (const KeyframeId& neighbour : covisibility.BestCovisible(id, options.group_size)) {
        const auto it = scores.find(neighbour);
        if (it == scores.end()) continue;
        candidate.group_score += it->second;
        if (it->second > candidate.score)
          candidate = {neighbour, it->second, candidate.group_score};
      }
    }
    best_group_score = std::max(best_group_score, candidate.group_score);
    PlaceCandidate& stored = best_of_group.try_emplace(candidate.keyframe, candidate).first->second;
    if (candidate.group_score > stored.group_score) stored = candidate;
  }
  std::vector<PlaceCandidate> candidates;
  for (const auto& [id, candidate] : best_of_group) {
    if (candidate.group_score >= options.min_group_score_ratio * best_group_score) {
      candidates.push_back(candidate);
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const PlaceCandidate& a, const PlaceCandidate& b) {
              if (a.group_score != b.group_score) return a.group_score > b.group_score;
              return a.keyframe < b.keyframe;
            });
  if (static_cast<int>(candidates.size()) > options.max_candidates) {
    candidates.resize(options.max_candidates);
  }
  return candidates;
}

}  // namespace arucoslam
