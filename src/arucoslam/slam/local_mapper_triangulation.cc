// LocalMapper::TriangulateNewPoints: unmatched keypoints of the new keyframe are matched
// with those of covisible keyframes along epipolar lines and triangulated when the point
// passes the parallax, depth, reprojection and scale-consistency checks.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "arucoslam/feature/orb_matcher.h"
#include "arucoslam/geometry/triangulation.h"
#include "arucoslam/slam/local_mapper.h"

namespace arucoslam {
namespace {

double Sigma2(const Keyframe& keyframe, int index) {
  const double sigma = keyframe.SigmaPx(index);
  return sigma * sigma;
}

// Matches of unmatched keypoints of `kf1` (index1) and `kf2` (index2) that lie within the
// epipolar band, away from the epipole, pass the ratio test and agree in rotation.
std::vector<FeatureMatch> MatchAlongEpipolarLines(const Keyframe& kf1, const Keyframe& kf2,
                                                  const LocalMapperOptions& options) {
  const Rigid3 cam2_from_cam1 = kf2.cam_from_world * kf1.cam_from_world.Inverse();
  Eigen::Matrix3d skew;
  const Eigen::Vector3d& t = cam2_from_cam1.translation;
  skew << 0, -t.z(), t.y(), t.z(), 0, -t.x(), -t.y(), t.x(), 0;
  const Eigen::Matrix3d essential = skew * cam2_from_cam1.RotationMatrix();
  const double focal2 = 0.5 * (kf2.camera.fx + kf2.camera.fy);
  const bool has_epipole = t.z() > 1e-9;
  const Eigen::Vector2d epipole = has_epipole ? Eigen::Vector2d(t.x() / t.z(), t.y() / t.z())
                                              : Eigen::Vector2d::Zero();
  // The unmatched keypoints of kf2 away from the epipole, with their epipolar band: what
  // the inner loop needs, packed column-wise in kf2's keypoint order so that the band test
  // runs over all of them in vector instructions.
  std::vector<int> candidates;
  for (std::size_t j = 0; j < kf2.map_point_ids.size(); ++j) {
    if (kf2.map_point_ids[j].IsValid()) continue;
    const int index = static_cast<int>(j);
    const Eigen::Vector2d& x2 = kf2.features.undistorted[j];
    if (has_epipole && (x2 - epipole).norm() * focal2 <
                           options.min_epipole_distance_px * kf2.SigmaPx(index)) {
      continue;
    }
    candidates.push_back(index);
  }
  const Eigen::Index num_candidates = static_cast<Eigen::Index>(candidates.size());
  Eigen::ArrayXd x2s(num_candidates), y2s(num_candidates), max_distance2_px(num_candidates);
  for (Eigen::Index k = 0; k < num_candidates; ++k) {
    const Eigen::Vector2d& x2 = kf2.features.undistorted[candidates[k]];
    x2s[k] = x2.x();
    y2s[k] = x2.y();
    max_distance2_px[k] = options.epipolar_chi2 * Sigma2(kf2, candidates[k]);
  }
  Eigen::ArrayXd distance2_px(num_candidates);  // squared distance to the line, pixels
  std::vector<int> best_for_2(kf2.features.size(), -1);
  std::vector<int> best_distance_2(kf2.features.size(), std::numeric_limits<int>::max());
  for (std::size_t i = 0; i < kf1.map_point_ids.size(); ++i) {
    if (kf1.map_point_ids[i].IsValid()) continue;
    const Eigen::Vector3d line = essential * kf1.features.undistorted[i].homogeneous();
    const double norm2 = line.head<2>().squaredNorm();
    if (norm2 <= 0.0) continue;
    distance2_px = (line.x() * x2s + line.y() * y2s + line.z()).square() / norm2 * focal2 * focal2;
    const std::uint8_t* descriptor1 = kf1.features.Descriptor(static_cast<int>(i));
    int best = -1, best_distance = options.max_match_distance + 1, second = 256;
    for (Eigen::Index k = 0; k < num_candidates; ++k) {
      if (distance2_px[k] > max_distance2_px[k]) continue;
      const int candidate = candidates[k];
      const int distance = HammingDistance(descriptor1, kf2.features.Descriptor(candidate));
      if (distance < best_distance) {
        second = best_distance;
        best_distance = distance;
        best = candidate;
      } else if (distance < second) {
        second = distance;
      }
    }
    if (best < 0 || best_distance >= options.match_ratio * second) continue;
    if (best_distance < best_distance_2[best]) {
      best_distance_2[best] = best_distance;
      best_for_2[best] = static_cast<int>(i);
    }
  }
  std::vector<FeatureMatch> matches;
  for (std::size_t j = 0; j < best_for_2.size(); ++j) {
    if (best_for_2[j] >= 0) matches.push_back({best_for_2[j], static_cast<int>(j), best_distance_2[j]});
  }
  std::vector<float> angles1, angles2;
  for (const cv::KeyPoint& keypoint : kf1.features.keypoints) angles1.push_back(keypoint.angle);
  for (const cv::KeyPoint& keypoint : kf2.features.keypoints) angles2.push_back(keypoint.angle);
  return FilterByRotationConsistency(matches, angles1, angles2);
}

struct TriangulatedMatch {
  Eigen::Vector3d p_in_world;
  double parallax_cos = 1.0;  // cosine of the angle between the two viewing rays
};

// The point of a match when it passes every check, else nullopt.
std::optional<TriangulatedMatch> TriangulateMatch(const Keyframe& kf1, const Keyframe& kf2,
                                                const FeatureMatch& match,
                                                const LocalMapperOptions& options) {
  const Eigen::Vector2d& x1 = kf1.features.undistorted[match.index1];
  const Eigen::Vector2d& x2 = kf2.features.undistorted[match.index2];
  const Eigen::Vector3d ray1 =
      kf1.cam_from_world.rotation.conjugate() * x1.homogeneous().normalized();
  const Eigen::Vector3d ray2 =
      kf2.cam_from_world.rotation.conjugate() * x2.homogeneous().normalized();
  const double parallax_cos = ray1.dot(ray2);
  if (parallax_cos >= options.max_parallax_cos) return std::nullopt;
  const std::optional<Eigen::Vector3d> point =
      TriangulateDlt(kf1.cam_from_world, kf2.cam_from_world, x1, x2);
  if (!point) return std::nullopt;
  const TriangulationQuality quality = EvaluateTriangulation(
      *point, kf1.cam_from_world, kf2.cam_from_world, x1, x2, kf1.camera.fx, kf1.camera.fy);
  if (!(quality.depth1 > 0.0) || !(quality.depth2 > 0.0)) return std::nullopt;
  if (quality.error1_sq_px > options.reprojection_chi2 * Sigma2(kf1, match.index1) ||
      quality.error2_sq_px > options.reprojection_chi2 * Sigma2(kf2, match.index2)) {
    return std::nullopt;
  }
  const double distance1 = (*point - kf1.CameraCenter()).norm();
  const double distance2 = (*point - kf2.CameraCenter()).norm();
  if (distance1 <= 0.0 || distance2 <= 0.0) return std::nullopt;
  const double distance_ratio = distance2 / distance1;
  const double octave_ratio = kf1.SigmaPx(match.index1) / kf2.SigmaPx(match.index2);
  const double factor = options.scale_consistency_factor * kf1.features.pyramid.scale_factor;
  if (distance_ratio * factor < octave_ratio || distance_ratio > octave_ratio * factor) {
    return std::nullopt;
  }
  return TriangulatedMatch{*point, parallax_cos};
}

double MedianDepth(const MapData& data, const Keyframe& keyframe) {
  std::vector<double> depths;
  for (const MapPointId& id : keyframe.map_point_ids) {
    if (const MapPoint* point = data.FindMapPoint(id)) {
      depths.push_back((keyframe.cam_from_world * point->p_in_world).z());
    }
  }
  if (depths.empty()) return 0.0;
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  return depths[depths.size() / 2];
}

// Whether `p_in_world` reprojects into `keyframe`'s keypoint `index` within the test.
bool Reprojects(const Keyframe& keyframe, int index, const Eigen::Vector3d& p_in_world,
                double chi2) {
  return SquaredReprojectionErrorPx(keyframe.cam_from_world * p_in_world,
                                    keyframe.features.undistorted[index], keyframe.camera.fx,
                                    keyframe.camera.fy) < chi2 * Sigma2(keyframe, index);
}

struct NewPoint {
  KeyframeId other;
  int index1 = 0;
  int index2 = 0;
  Eigen::Vector3d p_in_world;
  double parallax_cos = 1.0;
};

}  // namespace

int LocalMapper::TriangulateNewPoints(KeyframeId keyframe) {
  // Copies of the keyframes, so that matching runs without holding the map's lock.
  std::optional<Keyframe> current;
  std::vector<Keyframe> neighbours;
  map_.Read([&](const MapData& data) {
    const Keyframe* found = data.FindKeyframe(keyframe);
    if (found == nullptr) return;
    current = *found;
    for (const KeyframeId& id :
         data.covisibility().BestCovisible(keyframe, options_.triangulation_neighbours)) {
      const Keyframe& other = *data.FindKeyframe(id);
      const double baseline = (other.CameraCenter() - found->CameraCenter()).norm();
      const double depth = MedianDepth(data, other);
      if (depth > 0.0 && baseline / depth >= options_.min_baseline_depth_ratio) {
        neighbours.push_back(other);
      }
    }
  });
  if (!current) return 0;
  // Each keypoint is triangulated with the neighbour that sees it under the widest parallax.
  // Taking the first neighbour that passes (the most covisible, usually the nearest) made
  // the parallax test select, among low-parallax matches, those whose noise widened the
  // parallax: their points lay too near, and the map's scale shrank as the camera moved.
  // With `multi_view_check`, the other pairs of the keypoint must agree with that point.
  // pairs[i]: every passing pair of keypoint i, with its neighbour's index in `neighbours`.
  std::vector<std::vector<std::pair<std::size_t, NewPoint>>> pairs(current->features.size());
  for (std::size_t n = 0; n < neighbours.size(); ++n) {
    const Keyframe& other = neighbours[n];
    for (const FeatureMatch& match : MatchAlongEpipolarLines(*current, other, options_)) {
      if (const auto point = TriangulateMatch(*current, other, match, options_)) {
        pairs[match.index1].emplace_back(
            n, NewPoint{other.id, match.index1, match.index2, point->p_in_world,
                        point->parallax_cos});
      }
    }
  }
  std::vector<NewPoint> candidates;
  for (const auto& keypoint_pairs : pairs) {
    if (keypoint_pairs.empty()) continue;
    const auto widest = std::min_element(
        keypoint_pairs.begin(), keypoint_pairs.end(),
        [](const auto& a, const auto& b) { return a.second.parallax_cos < b.second.parallax_cos; });
    const bool consistent =
        !options_.multi_view_check ||
        std::all_of(keypoint_pairs.begin(), keypoint_pairs.end(), [&](const auto& pair) {
          return &pair == &*widest ||
                 Reprojects(neighbours[pair.first], pair.second.index2,
                            widest->second.p_in_world, options_.reprojection_chi2);
        });
    if (consistent) candidates.push_back(widest->second);
  }
  return map_.Write([&](MapData& data) {
    int created = 0;
    for (const NewPoint& candidate : candidates) {
      const Keyframe* kf1 = data.FindKeyframe(keyframe);
      const Keyframe* kf2 = data.FindKeyframe(candidate.other);
      if (kf1 == nullptr || kf2 == nullptr || kf1->map_point_ids[candidate.index1].IsValid() ||
          kf2->map_point_ids[candidate.index2].IsValid()) {
        continue;
      }
      MapPoint point;
      point.p_in_world = candidate.p_in_world;
      point.reference_keyframe = keyframe;
      const MapPointId id = data.AddMapPoint(point);
      data.AddObservation(keyframe, candidate.index1, id);
      data.AddObservation(candidate.other, candidate.index2, id);
      data.UpdateDescriptor(id);
      data.UpdateNormalAndDepth(id);
      recent_points_.emplace_back(id, num_processed_);
      ++created;
    }
    return created;
  });
}

}  // namespace arucoslam
