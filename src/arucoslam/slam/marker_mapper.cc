#include "arucoslam/slam/marker_mapper.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace arucoslam {
namespace {

// Two marker orientations this far apart are different IPPE branches, radians.
constexpr double kDistinctRotationRad = 0.1;

// Whether a camera at `cam_from_world` can have detected `landmark`: the marker ahead of it,
// its printed side readable (within max_view_angle_deg), and its centre projected within one
// image size of the image (room for a drifted pose). A misread elsewhere in the image fails
// this; local BA would move the keyframe to fit it.
bool CouldHaveSeen(const MarkerLandmark& landmark, const Rigid3& cam_from_world,
                   const CameraModel& camera, double max_view_angle_deg) {
  const Eigen::Vector3d centre_in_cam = cam_from_world * landmark.world_from_marker.translation;
  if (!(centre_in_cam.z() > 0.0)) return false;
  const double min_view_cosine = std::cos(max_view_angle_deg * M_PI / 180.0);
  if (!SeesPrintedSide(landmark.world_from_marker, cam_from_world.Inverse().translation,
                       min_view_cosine)) {
    return false;
  }
  const double u = camera.fx * centre_in_cam.x() / centre_in_cam.z() + camera.cx;
  const double v = camera.fy * centre_in_cam.y() / centre_in_cam.z() + camera.cy;
  return u > -camera.width && u < 2.0 * camera.width && v > -camera.height &&
         v < 2.0 * camera.height;
}

// Whether the camera pose a detection of `landmark` gives by itself (the IPPE solution nearer
// the keyframe) lies within `max_offset_ratio` times the marker's distance of the keyframe's
// centre. True when the detection gives no pose.
bool DetectionAgreesWithPose(const MarkerLandmark& landmark, const MarkerObservation& observation,
                             const Rigid3& cam_from_world, const CameraModel& camera,
                             const MarkerPoseOptions& pose_options, double max_offset_ratio) {
  const std::optional<MarkerPose> pose =
      EstimateMarkerPose(observation.AsDetection(), landmark.size, camera, pose_options);
  if (!pose) return true;
  const Eigen::Vector3d centre = cam_from_world.Inverse().translation;
  const double max_offset =
      max_offset_ratio * (landmark.world_from_marker.translation - centre).norm();
  for (int s = 0; s < pose->num_solutions; ++s) {
    const Eigen::Vector3d implied =
        (landmark.world_from_marker * pose->solutions[s].cam_from_marker.Inverse()).translation;
    if ((implied - centre).norm() <= max_offset) return true;
  }
  return false;
}

}  // namespace

MarkerMapper::MarkerMapper(const MarkerMap& known, const MarkerMapperOptions& options)
    : options_(options),
      dictionary_(known.dictionary),
      unknown_size_(options.map_unknown ? UnknownMarkerSize(known, options.unknown_marker_size_m)
                                        : 0.0),
      landmarks_(MarkerLandmarks::FromMarkerMap(known)) {}

double UnknownMarkerSize(const MarkerMap& known, double configured_m) {
  if (configured_m > 0.0 || known.markers.empty()) return configured_m;
  return known.markers.begin()->second.size;
}

std::vector<MarkerId> MarkerMapper::AddKeyframe(KeyframeId keyframe, const Rigid3& cam_from_world,
                                                const CameraModel& camera,
                                                const std::vector<MarkerObservation>& markers) {
  const auto found = live_.find(keyframe);
  const int record = found != live_.end() ? found->second : next_record_++;
  live_[keyframe] = record;
  // The record keeps the detections of unmapped markers and those of landmarks the pose
  // could have made (a misread joins no adjustment, not even once the keyframe is retired).
  std::vector<MarkerObservation> kept;
  for (const MarkerObservation& observation : markers) {
    const MarkerLandmark* landmark = landmarks_.Find(observation.marker_id);
    if (landmark == nullptr ||
        (CouldHaveSeen(*landmark, cam_from_world, camera, options_.max_view_angle_deg) &&
         DetectionAgreesWithPose(*landmark, observation, cam_from_world, camera,
                                 options_.marker_pose, options_.max_detection_offset_ratio))) {
      kept.push_back(observation);
    }
  }
  records_[record] = {keyframe, generation_, cam_from_world, camera, std::move(kept)};
  std::vector<MarkerId> initialised;
  for (const MarkerObservation& observation : records_.at(record).markers) {
    if (landmarks_.Find(observation.marker_id) != nullptr) {
      landmarks_.AddObservation(observation.marker_id, keyframe, observation.corners_px);
    } else if (unknown_size_ > 0.0) {
      Observe(record, observation, &initialised);
    }
  }
  return initialised;
}

bool MarkerMapper::WantsMarkerView(const Rigid3& cam_from_world,
                                   const std::vector<MarkerObservation>& markers) const {
  const Eigen::Vector3d centre = cam_from_world.Inverse().translation;
  bool maps_something = false;
  double nearest = std::numeric_limits<double>::infinity();
  for (const MarkerObservation& observation : markers) {
    const MarkerLandmark* landmark = landmarks_.Find(observation.marker_id);
    if (landmark == nullptr || !landmark->fixed) maps_something = true;
    if (landmark != nullptr) {
      nearest = std::min(nearest, (landmark->world_from_marker.translation - centre).norm());
    }
  }
  if (!maps_something || !std::isfinite(nearest)) return false;
  const double min_translation = options_.marker_view_min_translation_fraction * nearest;
  const double min_rotation = options_.marker_view_min_rotation_deg * M_PI / 180.0;
  for (const auto& [index, record] : records_) {
    if (record.generation != kMarkerViewGeneration) continue;
    const bool near =
        (record.cam_from_world.Inverse().translation - centre).norm() < min_translation;
    const bool turned = RotationAngle(record.cam_from_world.rotation *
                                      cam_from_world.rotation.inverse()) >= min_rotation;
    if (near && !turned) return false;
  }
  return true;
}

bool MarkerMapper::AddMarkerView(const Rigid3& cam_from_world, const CameraModel& camera,
                                 const std::vector<MarkerObservation>& markers,
                                 std::vector<MarkerId>* initialised) {
  if (!WantsMarkerView(cam_from_world, markers)) return false;
  const int record = next_record_++;
  records_[record] = {KeyframeId(), kMarkerViewGeneration, cam_from_world, camera, markers};
  ++num_marker_views_;
  for (const MarkerObservation& observation : markers) {
    if (!landmarks_.Contains(observation.marker_id) && unknown_size_ > 0.0) {
      Observe(record, observation, initialised);
    }
  }
  return true;
}

bool MarkerMapper::AdoptWorldOrigin(const std::vector<MarkerDetection>& detections,
                                    const CameraModel& camera) {
  if (!landmarks_.empty() || !(unknown_size_ > 0.0) || detections.empty()) return false;
  const auto area = [](const MarkerDetection& detection) {  // shoelace formula, pixels^2
    double twice = 0.0;
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector2d& a = detection.corners[c];
      const Eigen::Vector2d& b = detection.corners[(c + 1) % 4];
      twice += a.x() * b.y() - b.x() * a.y();
    }
    return std::abs(twice) / 2.0;
  };
  const MarkerDetection* largest = &detections.front();
  for (const MarkerDetection& detection : detections) {
    if (area(detection) > area(*largest)) largest = &detection;
  }
  // Its corners must fit a square (not a false detection) to be the origin.
  const std::optional<MarkerPose> pose =
      EstimateMarkerPose(*largest, unknown_size_, camera, options_.marker_pose);
  if (!pose || pose->Best().reprojection_rms_px > options_.max_initial_rms_px) return false;
  MarkerLandmark origin;
  origin.id = MarkerId(largest->id);
  origin.size = unknown_size_;
  origin.world_from_marker = Rigid3();
  origin.fixed = true;
  return landmarks_.Add(std::move(origin));
}

int MarkerMapper::NumViews(MarkerId id) const {
  const MarkerLandmark* landmark = landmarks_.Find(id);
  int count = landmark != nullptr ? static_cast<int>(landmark->observations.size()) : 0;
  for (const auto& [index, record] : records_) {
    if (record.keyframe.IsValid()) continue;
    for (const MarkerObservation& observation : record.markers) {
      if (observation.marker_id == id) ++count;
    }
  }
  return count;
}

void MarkerMapper::EraseKeyframe(KeyframeId keyframe) {
  landmarks_.EraseKeyframe(keyframe);
  const auto found = live_.find(keyframe);
  if (found == live_.end()) return;
  const int record = found->second;
  live_.erase(found);
  records_.erase(record);
  for (auto& [id, views] : pending_) {
    std::erase_if(views, [&](const View& view) { return view.record == record; });
  }
  std::erase_if(pending_, [](const auto& entry) { return entry.second.empty(); });
}

void MarkerMapper::Retire(KeyframeId keyframe) {
  landmarks_.EraseKeyframe(keyframe);  // its views now come from the record
  const auto found = live_.find(keyframe);
  if (found == live_.end()) return;
  Record& record = records_.at(found->second);
  record.keyframe = KeyframeId();
  if (record.markers.empty()) records_.erase(found->second);
  live_.erase(found);
}

void MarkerMapper::SyncKeyframes(const MapData& map) {
  std::vector<KeyframeId> gone;
  for (const auto& [id, record] : live_) {
    const Keyframe* keyframe = map.FindKeyframe(id);
    if (keyframe == nullptr) {
      gone.push_back(id);
    } else {
      records_.at(record).cam_from_world = keyframe->cam_from_world;
    }
  }
  for (const KeyframeId& id : gone) Retire(id);
}

int MarkerMapper::CloseMap() {
  std::vector<KeyframeId> live;
  for (const auto& [id, record] : live_) {
    live.push_back(id);
    records_.at(record).closed_as = id;
  }
  for (const KeyframeId& id : live) Retire(id);
  return generation_++;
}

int MarkerMapper::ReviveClosedMap(int generation, const std::map<KeyframeId, KeyframeId>& new_ids) {
  int revived = 0;
  for (auto& [index, record] : records_) {
    if (record.generation != generation || record.keyframe.IsValid()) continue;
    const auto found = new_ids.find(record.closed_as);
    if (!record.closed_as.IsValid() || found == new_ids.end() || live_.count(found->second)) {
      continue;
    }
    record.keyframe = found->second;
    record.generation = generation_;
    record.closed_as = KeyframeId();
    live_[record.keyframe] = index;
    for (const MarkerObservation& observation : record.markers) {
      if (landmarks_.Contains(observation.marker_id)) {
        landmarks_.AddObservation(observation.marker_id, record.keyframe, observation.corners_px);
      }
    }
    ++revived;
  }
  return revived;
}

void MarkerMapper::ApplySimilarity(const Sim3& new_from_old, const std::set<KeyframeId>* stay) {
  for (auto& [id, record] : records_) {
    if (record.generation != generation_) continue;
    if (stay != nullptr && stay->count(record.keyframe) != 0) continue;
    record.cam_from_world = new_from_old.TransformPose(record.cam_from_world.Inverse()).Inverse();
  }
}

int MarkerMapper::NumRetiredViews() const {
  int count = 0;
  for (const auto& [id, record] : records_) {
    if (!record.keyframe.IsValid()) count += static_cast<int>(record.markers.size());
  }
  return count;
}

void MarkerMapper::Observe(int record, const MarkerObservation& observation,
                           std::vector<MarkerId>* initialised) {
  const std::optional<MarkerPose> pose = EstimateMarkerPose(
      observation.AsDetection(), unknown_size_, records_.at(record).camera, options_.marker_pose);
  if (!pose || pose->Best().reprojection_rms_px > options_.max_initial_rms_px) return;
  std::vector<View>& views = pending_[observation.marker_id];
  std::erase_if(views, [&](const View& view) { return view.record == record; });
  views.push_back({record, observation.corners_px, *pose});
  if (static_cast<int>(views.size()) > options_.max_pending_views) views.erase(views.begin());
  if (TryInitialise(observation.marker_id)) initialised->push_back(observation.marker_id);
}

std::vector<const MarkerMapper::View*> MarkerMapper::AgreeingViews(
    const std::vector<View>& views, const Rigid3& world_from_marker) const {
  std::vector<const View*> agreeing;
  for (const View& view : views) {
    const Rigid3 world_from_cam = records_.at(view.record).cam_from_world.Inverse();
    for (int s = 0; s < view.pose.num_solutions; ++s) {
      const Eigen::Vector3d& in_cam = view.pose.solutions[s].cam_from_marker.translation;
      const double tolerance = options_.max_view_disagreement_m +
                               options_.max_view_disagreement_fraction * in_cam.norm();
      if ((world_from_cam * in_cam - world_from_marker.translation).norm() <= tolerance) {
        agreeing.push_back(&view);
        break;
      }
    }
  }
  return agreeing;
}

double MarkerMapper::ViewsSquaredError(const std::vector<const View*>& views,
                                       const Rigid3& world_from_marker) const {
  const std::array<Eigen::Vector3d, 4> corners = SquareCorners(unknown_size_);
  double sum = 0.0;
  for (const View* view : views) {
    const Record& record = records_.at(view->record);
    const double rms = MarkerReprojectionRms(
        record.camera, record.cam_from_world * world_from_marker, corners, view->corners_px);
    sum += rms * rms;
  }
  return sum;
}

bool MarkerMapper::TryInitialise(MarkerId id) {
  const std::vector<View>& views = pending_.at(id);
  if (static_cast<int>(views.size()) < options_.min_consistent_views) return false;
  // Every IPPE solution of every view is a candidate; the one most views agree with wins,
  // then the one that explains those views' corners best.
  std::vector<Rigid3> candidates;
  for (const View& view : views) {
    const Rigid3 world_from_cam = records_.at(view.record).cam_from_world.Inverse();
    for (int s = 0; s < view.pose.num_solutions; ++s) {
      candidates.push_back(world_from_cam * view.pose.solutions[s].cam_from_marker);
    }
  }
  std::size_t best_count = 0;
  double best_error = std::numeric_limits<double>::infinity();
  Rigid3 best;
  std::vector<const View*> agreeing;
  for (const Rigid3& candidate : candidates) {
    std::vector<const View*> candidate_views = AgreeingViews(views, candidate);
    if (candidate_views.size() < best_count) continue;
    const double error = ViewsSquaredError(candidate_views, candidate);
    if (candidate_views.size() > best_count || error < best_error) {
      best_count = candidate_views.size();
      best_error = error;
      best = candidate;
      agreeing = std::move(candidate_views);
    }
  }
  if (static_cast<int>(best_count) < options_.min_consistent_views) return false;
  // IPPE's mirror ambiguity: the best candidate of another orientation (the other solution
  // of close views) is refined too; the two must be told apart by the views' corners, or
  // the marker waits for more views (up to max_pending_views).
  std::optional<Rigid3> mirror;
  double mirror_error = std::numeric_limits<double>::infinity();
  for (const Rigid3& candidate : candidates) {
    if (RotationAngle(candidate.rotation * best.rotation.inverse()) < kDistinctRotationRad) {
      continue;
    }
    const double error = ViewsSquaredError(agreeing, candidate);
    if (error < mirror_error) {
      mirror_error = error;
      mirror = candidate;
    }
  }
  Rigid3 chosen = RefineNewMarker(best, agreeing);
  if (mirror) {
    const Rigid3 other = RefineNewMarker(*mirror, agreeing);
    const double count = static_cast<double>(agreeing.size());
    double chosen_rms = std::sqrt(ViewsSquaredError(agreeing, chosen) / count);
    double other_rms = std::sqrt(ViewsSquaredError(agreeing, other) / count);
    if (other_rms < chosen_rms) {
      std::swap(chosen_rms, other_rms);
      chosen = other;
    }
    const bool distinct =
        RotationAngle(chosen.rotation * other.rotation.inverse()) < kDistinctRotationRad ||
        (chosen_rms < options_.marker_pose.ambiguity_ratio * other_rms &&
         other_rms >= options_.marker_pose.min_distinct_error_px);
    if (!distinct && static_cast<int>(views.size()) < options_.max_pending_views) return false;
  }
  MarkerLandmark landmark;
  landmark.id = id;
  landmark.size = unknown_size_;
  landmark.world_from_marker = chosen;
  landmark.fixed = false;
  for (const View* view : agreeing) {
    const Record& record = records_.at(view->record);
    if (record.keyframe.IsValid()) landmark.observations[record.keyframe] = view->corners_px;
  }
  landmarks_.Add(std::move(landmark));
  pending_.erase(id);
  return true;
}

MarkerMap MarkerMapper::ToMarkerMap() const { return landmarks_.ToMarkerMap(dictionary_); }

}  // namespace arucoslam
