#include "arucoslam/slam/world_rotation_vote.h"

#include <cmath>
#include <stdexcept>

namespace arucoslam {
namespace {

// Whether two unit quaternions are within the angle whose half-angle cosine is `cos_half`
// (|a.b| is the cosine of half the angle between them: no trigonometry per pair).
bool Within(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b, double cos_half) {
  return std::abs(a.coeffs().dot(b.coeffs())) >= cos_half;
}

}  // namespace

WorldRotationVote::WorldRotationVote(const WorldRotationVoteOptions& options)
    : options_(options) {
  if (!options_.Check()) throw std::invalid_argument("WorldRotationVote: invalid options");
}

void WorldRotationVote::Add(const Rigid3& cam_from_map, const Rigid3& world_from_cam_a,
                            const Rigid3& world_from_cam_b) {
  View view;
  view.hypotheses[0] = (world_from_cam_a.rotation * cam_from_map.rotation).normalized();
  view.hypotheses[1] = (world_from_cam_b.rotation * cam_from_map.rotation).normalized();
  views_.push_back(view);
  if (static_cast<int>(views_.size()) > options_.max_views) views_.erase(views_.begin());
  Decide();
}

void WorldRotationVote::Clear() {
  views_.clear();
  decided_.reset();
}

void WorldRotationVote::Decide() {
  decided_.reset();
  const int n = static_cast<int>(views_.size());
  if (n < options_.min_support) return;
  const double agreement = options_.agreement_deg * M_PI / 180.0;
  const double cos_half = std::cos(agreement / 2.0);
  const double cos_half_rival = std::cos(agreement);  // twice the agreement angle
  // Support of a hypothesis: the views with a solution within the agreement angle of it.
  const auto support = [&](const Eigen::Quaterniond& hypothesis) {
    int count = 0;
    for (const View& view : views_) {
      if (Within(hypothesis, view.hypotheses[0], cos_half) ||
          Within(hypothesis, view.hypotheses[1], cos_half)) {
        ++count;
      }
    }
    return count;
  };
  std::vector<int> supports(2 * n);
  int winner = 0;
  for (int h = 0; h < 2 * n; ++h) {
    supports[h] = support(views_[h / 2].hypotheses[h % 2]);
    if (supports[h] > supports[winner]) winner = h;
  }
  const Eigen::Quaterniond& best = views_[winner / 2].hypotheses[winner % 2];
  int rival = 0;
  for (int h = 0; h < 2 * n; ++h) {
    if (!Within(best, views_[h / 2].hypotheses[h % 2], cos_half_rival)) {
      rival = std::max(rival, supports[h]);
    }
  }
  if (supports[winner] < options_.min_support ||
      supports[winner] < options_.min_margin * rival) {
    return;
  }
  // Mean of the agreeing solutions (quaternions on the winner's hemisphere).
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (const View& view : views_) {
    for (const Eigen::Quaterniond& hypothesis : view.hypotheses) {
      if (!Within(best, hypothesis, cos_half)) continue;
      const double sign = best.coeffs().dot(hypothesis.coeffs()) < 0.0 ? -1.0 : 1.0;
      sum += sign * hypothesis.coeffs();
      break;
    }
  }
  Eigen::Quaterniond mean;
  mean.coeffs() = sum.normalized();
  decided_ = mean;
}

}  // namespace arucoslam
