#include "arucoslam/slam/world_alignment.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <optional>

namespace arucoslam {
namespace {

struct WeightedAnchor {
  Eigen::Vector3d centre_in_map;
  Eigen::Vector3d centre_in_world;
  Eigen::Matrix3d world_from_map_rotation;  // what this anchor alone says
  double weight = 1.0;
};

// Nearest rotation to a 3x3 matrix (projection through the SVD, determinant +1).
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

// Weighted similarity fit; nullopt when the map centres do not spread.
std::optional<Sim3> Fit(const std::vector<WeightedAnchor>& anchors, const std::vector<bool>& use,
                        const WorldAlignmentOptions& options, WorldAlignmentMethod* method) {
  double total = 0.0;
  Eigen::Vector3d mean_map = Eigen::Vector3d::Zero(), mean_world = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    if (!use[i]) continue;
    total += anchors[i].weight;
    mean_map += anchors[i].weight * anchors[i].centre_in_map;
    mean_world += anchors[i].weight * anchors[i].centre_in_world;
  }
  if (!(total > 0.0)) return std::nullopt;
  mean_map /= total;
  mean_world /= total;
  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero(), scatter = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d rotation_sum = Eigen::Matrix3d::Zero();
  double map_variance = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    if (!use[i]) continue;
    const double w = anchors[i].weight;
    const Eigen::Vector3d a = anchors[i].centre_in_map - mean_map;
    const Eigen::Vector3d b = anchors[i].centre_in_world - mean_world;
    cross += w * b * a.transpose();
    scatter += w * a * a.transpose();
    rotation_sum += w * anchors[i].world_from_map_rotation;
    map_variance += w * a.squaredNorm();
    ++count;
  }
  if (count < 2 || !(map_variance > 1e-12 * total)) return std::nullopt;
  const Eigen::JacobiSVD<Eigen::Matrix3d> spread(scatter);
  const bool spread_out = count >= 3 && spread.singularValues()[1] >
                                            options.collinear_ratio * spread.singularValues()[0];
  Eigen::Matrix3d rotation;
  if (spread_out) {
    *method = WorldAlignmentMethod::kCentres;
    rotation = NearestRotation(cross);
  } else {
    *method = WorldAlignmentMethod::kOrientationsAndCentres;
    rotation = NearestRotation(rotation_sum);
  }
  // Given the rotation, the least-squares scale of the centred centres.
  const double scale = (cross.transpose() * rotation).trace() / map_variance;
  if (!(scale > 0.0)) return std::nullopt;
  return Sim3(scale, Eigen::Quaterniond(rotation), mean_world - scale * (rotation * mean_map));
}

double Residual(const WeightedAnchor& anchor, const Sim3& world_from_map) {
  return (anchor.centre_in_world - world_from_map * anchor.centre_in_map).norm();
}

// The fit with every usable anchor, or without the one whose removal fits the rest best
// when some anchor misses the threshold (three or more anchors).
std::optional<Sim3> RobustFit(const std::vector<WeightedAnchor>& anchors, std::vector<bool>* use,
                              const WorldAlignmentOptions& options, WorldAlignmentMethod* method) {
  const auto worst = [&](const Sim3& fit, const std::vector<bool>& subset) {
    double value = 0.0;
    for (std::size_t i = 0; i < anchors.size(); ++i) {
      if (subset[i]) value = std::max(value, Residual(anchors[i], fit));
    }
    return value;
  };
  std::optional<Sim3> fit = Fit(anchors, *use, options, method);
  const int count = static_cast<int>(std::count(use->begin(), use->end(), true));
  if (!fit || count < 3 || worst(*fit, *use) <= options.outlier_threshold_m) return fit;
  double best = worst(*fit, *use);
  std::size_t best_left_out = anchors.size();
  for (std::size_t j = 0; j < anchors.size(); ++j) {
    if (!(*use)[j]) continue;
    std::vector<bool> subset = *use;
    subset[j] = false;
    WorldAlignmentMethod subset_method;
    const std::optional<Sim3> candidate = Fit(anchors, subset, options, &subset_method);
    if (candidate && worst(*candidate, subset) < best) {
      best = worst(*candidate, subset);
      best_left_out = j;
    }
  }
  if (best_left_out == anchors.size()) return fit;
  (*use)[best_left_out] = false;
  return Fit(anchors, *use, options, method);
}

WorldAlignment SingleAnchor(const WorldAnchor& anchor) {
  WorldAlignment result;
  if (!(anchor.marker_depth_in_map > 0.0) || !(anchor.marker_depth_m > 0.0)) {
    result.failure =
        "one keyframe with a marker pose: the map's scale is unobservable without the "
        "marker's depth in the map";
    return result;
  }
  const double scale = anchor.marker_depth_m / anchor.marker_depth_in_map;
  const Rigid3 map_from_cam = anchor.cam_from_map.Inverse();
  const Eigen::Quaterniond rotation =
      anchor.world_from_cam.rotation * map_from_cam.rotation.inverse();
  result.world_from_map =
      Sim3(scale, rotation,
           anchor.world_from_cam.translation - scale * (rotation * map_from_cam.translation));
  result.method = WorldAlignmentMethod::kSingleAnchor;
  result.success = true;
  return result;
}

}  // namespace

WorldAlignment EstimateWorldFromMap(const std::vector<WorldAnchor>& anchors,
                                    const WorldAlignmentOptions& options) {
  WorldAlignment result;
  result.inliers.assign(anchors.size(), false);
  std::vector<WeightedAnchor> weighted;
  std::vector<bool> use;
  for (const WorldAnchor& anchor : anchors) {
    const Rigid3 map_from_cam = anchor.cam_from_map.Inverse();
    const double weight = anchor.ambiguous ? options.ambiguous_weight : 1.0;
    weighted.push_back(
        {map_from_cam.translation, anchor.world_from_cam.translation,
         (anchor.world_from_cam.rotation * map_from_cam.rotation.inverse()).toRotationMatrix(),
         weight});
    use.push_back(weight > 0.0);
  }
  const int usable = static_cast<int>(std::count(use.begin(), use.end(), true));
  if (!options.Check()) {
    result.failure = "invalid options";
    return result;
  }
  if (usable == 0) {
    result.failure = "no usable marker pose (ambiguous ones are left out)";
    return result;
  }
  if (usable == 1) {
    const std::size_t index = std::find(use.begin(), use.end(), true) - use.begin();
    WorldAlignment single = SingleAnchor(anchors[index]);
    single.inliers.assign(anchors.size(), false);
    single.inliers[index] = single.success;
    single.num_inliers = single.success ? 1 : 0;
    return single;
  }
  const std::optional<Sim3> fit = RobustFit(weighted, &use, options, &result.method);
  if (!fit) {
    result.method = WorldAlignmentMethod::kNone;
    result.failure = "the keyframes with marker poses share one camera centre";
    return result;
  }
  result.world_from_map = *fit;
  double sum = 0.0;
  for (std::size_t i = 0; i < weighted.size(); ++i) {
    const double residual = Residual(weighted[i], *fit);
    result.inliers[i] = use[i] && residual <= options.outlier_threshold_m;
    if (!result.inliers[i]) continue;
    ++result.num_inliers;
    sum += residual * residual;
  }
  result.rms_m = result.num_inliers > 0 ? std::sqrt(sum / result.num_inliers) : 0.0;
  result.success = result.num_inliers >= 2;
  if (!result.success)
    result.failure = "the marker poses disagree with the map beyond the threshold";
  return result;
}

void ApplyWorldAlignment(const Sim3& world_from_map, MapData* map, MarkerLandmarks* markers,
                         const std::set<KeyframeId>* stay) {
  const auto stays = [&](KeyframeId id) { return stay != nullptr && stay->count(id) != 0; };
  std::vector<std::pair<KeyframeId, Rigid3>> poses;
  for (const auto& [id, keyframe] : map->keyframes()) {
    if (stays(id)) continue;
    poses.emplace_back(id,
                       world_from_map.TransformPose(keyframe.cam_from_world.Inverse()).Inverse());
  }
  for (const auto& [id, pose] : poses) map->SetKeyframePose(id, pose);
  std::vector<MapPointId> points;
  for (const auto& [id, point] : map->map_points()) {
    const bool seen_by_staying = std::any_of(
        point.observations.begin(), point.observations.end(),
        [&](const auto& observation) { return stays(observation.first); });
    if (!seen_by_staying) points.push_back(id);
  }
  for (const MapPointId id : points) {
    map->SetMapPointPosition(id, world_from_map * map->FindMapPoint(id)->p_in_world);
    map->UpdateNormalAndDepth(id);
  }
  if (markers == nullptr) return;
  for (const auto& [id, landmark] : markers->landmarks()) {
    if (!landmark.fixed) {
      markers->SetPose(id, world_from_map.TransformPose(landmark.world_from_marker));
    }
  }
}

}  // namespace arucoslam
