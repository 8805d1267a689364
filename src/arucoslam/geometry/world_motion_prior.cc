#include "arucoslam/geometry/world_motion_prior.h"

namespace arucoslam {

void WorldMotionPrior::Add(double timestamp_s, const Rigid3& world_from_cam) {
  if (!fixes_.empty() && timestamp_s <= fixes_.back().timestamp_s) fixes_.clear();
  fixes_.push_back({timestamp_s, world_from_cam});
  while (timestamp_s - fixes_.front().timestamp_s > options_.max_span_s) fixes_.pop_front();
}

std::optional<Rigid3> WorldMotionPrior::Predict(double timestamp_s) const {
  if (fixes_.empty()) return std::nullopt;
  const Fix& newest = fixes_.back();
  const double age = timestamp_s - newest.timestamp_s;
  if (age <= 0.0 || age > options_.max_age_s) return std::nullopt;
  const Fix& oldest = fixes_.front();  // within max_span_s of the newest (Add)
  const double span = newest.timestamp_s - oldest.timestamp_s;
  if (span < options_.min_span_s) return std::nullopt;
  const Eigen::Vector3d omega =
      LogSO3(oldest.world_from_cam.rotation.conjugate() * newest.world_from_cam.rotation) / span;
  // Rotation and position extrapolated separately: the camera centre moves at the world
  // velocity between the fixes, the orientation turns at their relative angular rate.
  const Eigen::Vector3d velocity =
      (newest.world_from_cam.translation - oldest.world_from_cam.translation) / span;
  Rigid3 predicted;
  predicted.rotation = newest.world_from_cam.rotation * ExpSO3(omega * age);
  predicted.rotation.normalize();
  predicted.translation = newest.world_from_cam.translation + velocity * age;
  return predicted;
}

}  // namespace arucoslam
