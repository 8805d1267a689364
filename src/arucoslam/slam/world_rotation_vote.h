// The marker world's orientation relative to a keypoint map that is not aligned yet, voted
// by the ambiguous one-marker views the map tracked: their true IPPE solutions agree on it,
// the mirrored ones wander as the viewpoint changes.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct WorldRotationVoteOptions {
  double agreement_deg = 5.0;  // two views' hypotheses agree within this angle
  int min_support = 8;         // views agreeing with the winner, itself included
  // The winner needs this many times the support of the best rival hypothesis (one that
  // disagrees with it): mirrored solutions seen from a steady viewpoint agree too.
  double min_margin = 2.0;
  int max_views = 150;  // the newest are kept

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("agreement_deg", agreement_deg, 0.0);
    check.AtLeast("min_support", min_support, 2);
    check.Above("min_margin", min_margin, 1.0);
    check.AtLeast("max_views", max_views, min_support, "min_support");
    return check.ok();
  }
};

class WorldRotationVote {
 public:
  explicit WorldRotationVote(const WorldRotationVoteOptions& options = {});

  // One ambiguous view: the frame's pose in the keypoint map and the two world poses of
  // its marker (IPPE's solutions, in either order).
  void Add(const Rigid3& cam_from_map, const Rigid3& world_from_cam_a,
           const Rigid3& world_from_cam_b);
  void Clear();
  std::size_t NumViews() const { return views_.size(); }
  // The rotation world_from_map the views agree on (mean of the winner's supporters);
  // nullopt while the vote is undecided.
  const std::optional<Eigen::Quaterniond>& WorldFromMap() const { return decided_; }

 private:
  void Decide();

  struct View {
    Eigen::Quaterniond hypotheses[2];  // world_from_map from each solution
  };
  WorldRotationVoteOptions options_;
  std::vector<View> views_;
  std::optional<Eigen::Quaterniond> decided_;
};

}  // namespace arucoslam
