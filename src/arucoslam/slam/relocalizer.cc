#include "arucoslam/slam/relocalizer.h"

#include <algorithm>
#include <map>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <set>
#include <stdexcept>

#include "arucoslam/feature/feature_grid.h"
#include "arucoslam/slam/projection_queries.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// The frame's current 2D-3D correspondences, one slot per keypoint.
struct Correspondences {
  std::vector<MapPointId> ids;
  std::vector<Eigen::Vector3d> points;

  explicit Correspondences(std::size_t n) : ids(n), points(n, Eigen::Vector3d::Zero()) {}
  void Set(int keypoint, MapPointId id, const Eigen::Vector3d& p) {
    ids[keypoint] = id;
    points[keypoint] = p;
  }
  int Count() const {
    return static_cast<int>(
        std::count_if(ids.begin(), ids.end(), [](const MapPointId& id) { return id.IsValid(); }));
  }
};

// Matches the candidate keyframe's map points to the frame's keypoints inside shared
// vocabulary nodes: each keyframe feature takes its best frame feature (distance and ratio
// test), each frame feature keeps its closest keyframe feature.
void MatchByWords(const MapData& data, const Keyframe& keyframe,
                  const FeatureVector& keyframe_direct, const Frame& frame,
                  const FeatureVector& frame_direct, const RelocalizerOptions& options,
                  Correspondences* matched) {
  std::map<int, FeatureMatch> best_for_frame;  // frame feature -> match (index1 = keyframe)
  for (const FeatureVector::Group& group : keyframe_direct.groups) {
    const FeatureVector::Group* other = frame_direct.Find(group.node);
    if (other == nullptr) continue;
    for (const int a : group.features) {
      if (a >= static_cast<int>(keyframe.map_point_ids.size()) ||
          data.FindMapPoint(keyframe.map_point_ids[a]) == nullptr) {
        continue;
      }
      int best = 257, second = 257, best_b = -1;
      for (const int b : other->features) {
        const int d =
            HammingDistance(keyframe.features.Descriptor(a), frame.features.Descriptor(b));
        if (d < best) {
          second = best;
          best = d;
          best_b = b;
        } else if (d < second) {
          second = d;
        }
      }
      if (best_b < 0 || best > options.max_bow_distance || best >= options.bow_ratio * second) {
        continue;
      }
      const auto [it, inserted] = best_for_frame.try_emplace(best_b, FeatureMatch{a, best_b, best});
      if (!inserted && best < it->second.distance) it->second = {a, best_b, best};
    }
  }
  std::vector<FeatureMatch> matches;
  for (const auto& [b, match] : best_for_frame) matches.push_back(match);
  if (options.check_rotation) {
    std::vector<float> angles1, angles2;
    for (const cv::KeyPoint& k : keyframe.features.keypoints) angles1.push_back(k.angle);
    for (const cv::KeyPoint& k : frame.features.keypoints) angles2.push_back(k.angle);
    matches = FilterByRotationConsistency(matches, angles1, angles2);
  }
  for (const FeatureMatch& match : matches) {
    const MapPointId id = keyframe.map_point_ids[match.index1];
    matched->Set(match.index2, id, data.FindMapPoint(id)->p_in_world);
  }
}

// PnP with RANSAC on undistorted normalised coordinates; keeps only the inliers.
std::optional<Rigid3> SolvePnp(const Frame& frame, const RelocalizerOptions& options,
                               Correspondences* matched) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  std::vector<int> keypoint_of;
  for (std::size_t i = 0; i < matched->ids.size(); ++i) {
    if (!matched->ids[i].IsValid()) continue;
    const Eigen::Vector3d& p = matched->points[i];
    const Eigen::Vector2d& n = frame.features.undistorted[i];
    object.emplace_back(p.x(), p.y(), p.z());
    image.emplace_back(n.x(), n.y());
    keypoint_of.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(object.size()) < std::max(options.min_pnp_inliers, 6)) return std::nullopt;
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  const bool solved =
      cv::solvePnPRansac(object, image, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvec, tvec,
                         false, options.pnp_iterations, options.pnp_threshold_px / frame.camera.fx,
                         options.pnp_confidence, inliers, cv::SOLVEPNP_EPNP);
  if (!solved || static_cast<int>(inliers.size()) < options.min_pnp_inliers) return std::nullopt;
  Correspondences kept(matched->ids.size());
  for (const int k : inliers) {
    kept.Set(keypoint_of[k], matched->ids[keypoint_of[k]], matched->points[keypoint_of[k]]);
  }
  *matched = std::move(kept);
  cv::Mat rotation_cv;
  cv::Rodrigues(rvec, rotation_cv);
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  cv::cv2eigen(rotation_cv, rotation);
  cv::cv2eigen(tvec, translation);
  return Rigid3(rotation, translation);
}

// Pose-only optimisation over the correspondences; drops the outliers, returns the inliers
// (0 when the optimisation failed, leaving `pose` unchanged).
int Optimize(const Frame& frame, const PoseOptimizationOptions& options, Correspondences* matched,
             Rigid3* pose) {
  std::vector<PoseObservation> observations;
  std::vector<int> keypoint_of;
  for (std::size_t i = 0; i < matched->ids.size(); ++i) {
    if (!matched->ids[i].IsValid()) continue;
    const int index = static_cast<int>(i);
    observations.push_back(
        {matched->points[i], frame.UndistortedPixel(index), frame.SigmaPx(index)});
    keypoint_of.push_back(index);
  }
  if (observations.empty()) return 0;
  const PoseOptimizationResult result =
      OptimizePose(observations, *pose, PinholeIntrinsics::FromCamera(frame.camera), options);
  if (!result.success) return 0;
  *pose = result.cam_from_world;
  for (std::size_t k = 0; k < observations.size(); ++k) {
    if (!result.inliers[k]) matched->ids[keypoint_of[k]] = MapPointId();
  }
  return result.num_inliers;
}

// Projects the points of `keyframes` not matched yet into the frame at `pose` and adds the
// matches found around their predictions; returns how many were added.
int SearchByProjection(const MapData& data, const std::vector<KeyframeId>& keyframes,
                       const Frame& frame, const FeatureGrid& grid, const Rigid3& pose,
                       const ProjectionMatchOptions& search, Correspondences* matched) {
  const std::set<MapPointId> already(matched->ids.begin(), matched->ids.end());
  const Eigen::Vector3d center = pose.Inverse().translation;
  std::set<MapPointId> seen;
  ProjectionQueries set;
  std::vector<Eigen::Vector3d> positions;
  for (const KeyframeId& keyframe : keyframes) {
    for (const MapPointId& id : data.MapPointsOf(keyframe)) {
      if (already.count(id) != 0 || !seen.insert(id).second) continue;
      const MapPoint& point = *data.FindMapPoint(id);
      const std::optional<Eigen::Vector2d> pixel = frame.camera.Project(pose * point.p_in_world);
      if (!pixel || !frame.camera.InImage(*pixel)) continue;
      const double distance = (point.p_in_world - center).norm();
      if (!point.InDistanceRange(distance)) continue;
      set.Add(id, *pixel, point.PredictLevel(distance, frame.features.pyramid), point.descriptor,
              1.0, -1.0f);
      positions.push_back(point.p_in_world);
    }
  }
  set.Finalize();
  std::vector<bool> taken(matched->ids.size());
  for (std::size_t i = 0; i < taken.size(); ++i) taken[i] = matched->ids[i].IsValid();
  int added = 0;
  for (const FeatureMatch& match :
       MatchByProjection(frame.features, grid, set.queries, taken, search)) {
    matched->Set(match.index2, set.point_ids[match.index1], positions[match.index1]);
    ++added;
  }
  return added;
}

}  // namespace

bool RelocalizerOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("max_query_results", max_query_results, 1);
  check.Nested("grouping", grouping);
  check.AtLeast("max_bow_distance", max_bow_distance, 0);
  check.InRange("bow_ratio", bow_ratio, 0.0, 1.0, Interval::kOpenClosed);
  check.AtLeast("min_bow_matches", min_bow_matches, 6);
  check.Above("pnp_threshold_px", pnp_threshold_px, 0.0);
  check.AtLeast("pnp_iterations", pnp_iterations, 1);
  check.InRange("pnp_confidence", pnp_confidence, 0.0, 1.0, Interval::kOpen);
  check.AtLeast("min_pnp_inliers", min_pnp_inliers, 6);
  check.Nested("pose", pose);
  check.AtLeast("projection_neighbours", projection_neighbours, 0);
  check.Nested("wide_search", wide_search);
  check.Nested("narrow_search", narrow_search);
  check.AtLeast("min_inliers", min_inliers, 1);
  return check.ok();
}

Relocalizer::Relocalizer(const Map& map, const KeyframeDatabase& database,
                         const RelocalizerOptions& options)
    : map_(map), database_(database), options_(options) {
  if (!options.Check()) throw std::invalid_argument("RelocalizerOptions: bad options");
}

std::vector<KeyframeId> Relocalizer::Candidates(const BowVector& bow, int* num_matches) const {
  PlaceQueryOptions query;
  query.max_results = options_.max_query_results;
  const auto matches = database_.Query(bow, query);
  if (num_matches != nullptr) *num_matches = static_cast<int>(matches.size());
  const std::vector<PlaceCandidate> grouped = map_.Read([&](const MapData& data) {
    return GroupCandidates(matches, data.covisibility(), options_.grouping);
  });
  std::vector<KeyframeId> candidates;
  for (const PlaceCandidate& candidate : grouped) candidates.push_back(candidate.keyframe);
  return candidates;
}

std::optional<ImageWords> Relocalizer::QueryWords(const Frame& frame,
                                                  RelocalizationStats* stats) const {
  *stats = {};
  if (frame.features.empty() || frame.features.undistorted.size() != frame.features.size()) {
    return std::nullopt;
  }
  return database_.Transform(frame.features.descriptors);
}

std::optional<RelocalizationResult> Relocalizer::Relocalize(const Frame& frame,
                                                            RelocalizationStats* stats) const {
  RelocalizationStats local_stats;
  RelocalizationStats& s = stats != nullptr ? *stats : local_stats;
  const std::optional<ImageWords> words = QueryWords(frame, &s);
  if (!words) return std::nullopt;
  for (const KeyframeId& candidate : Candidates(words->bow, &s.num_database_matches)) {
    ++s.num_candidates;
    std::optional<RelocalizationResult> result = Verify(frame, words->direct, candidate, &s);
    if (result) return result;
  }
  return std::nullopt;
}

std::optional<RelocalizationResult> Relocalizer::RelocalizeAt(
    const Frame& frame, const std::vector<KeyframeId>& candidates,
    RelocalizationStats* stats) const {
  RelocalizationStats local_stats;
  RelocalizationStats& s = stats != nullptr ? *stats : local_stats;
  const std::optional<ImageWords> words = QueryWords(frame, &s);
  if (!words) return std::nullopt;
  for (const KeyframeId& candidate : candidates) {
    std::optional<FeatureVector> own;
    if (database_.Direct(candidate) == nullptr) {
      own = map_.Read([&](const MapData& data) -> std::optional<FeatureVector> {
        const Keyframe* keyframe = data.FindKeyframe(candidate);
        if (keyframe == nullptr) return std::nullopt;
        return database_.Transform(keyframe->features.descriptors).direct;
      });
      if (!own) continue;
    }
    ++s.num_candidates;
    std::optional<RelocalizationResult> result =
        Verify(frame, words->direct, candidate, &s, own ? &*own : nullptr);
    if (result) return result;
  }
  return std::nullopt;
}

std::optional<RelocalizationResult> Relocalizer::Verify(const Frame& frame,
                                                        const FeatureVector& direct,
                                                        KeyframeId candidate,
                                                        RelocalizationStats* stats,
                                                        const FeatureVector* keyframe_direct) const {
  if (keyframe_direct == nullptr) keyframe_direct = database_.Direct(candidate);
  if (keyframe_direct == nullptr) return std::nullopt;
  Correspondences matched(frame.features.size());
  std::vector<KeyframeId> local{candidate};
  const bool found = map_.Read([&](const MapData& data) {
    const Keyframe* keyframe = data.FindKeyframe(candidate);
    if (keyframe == nullptr) return false;
    MatchByWords(data, *keyframe, *keyframe_direct, frame, direct, options_, &matched);
    for (const KeyframeId& neighbour :
         data.covisibility().BestCovisible(candidate, options_.projection_neighbours)) {
      local.push_back(neighbour);
    }
    return true;
  });
  const int num_bow = matched.Count();
  stats->best_bow_matches = std::max(stats->best_bow_matches, num_bow);
  if (!found || num_bow < options_.min_bow_matches) return std::nullopt;
  std::optional<Rigid3> pose = SolvePnp(frame, options_, &matched);
  if (!pose) return std::nullopt;
  stats->best_pnp_inliers = std::max(stats->best_pnp_inliers, matched.Count());
  int inliers = Optimize(frame, options_.pose, &matched, &*pose);
  const FeatureGrid grid(frame.features);
  for (const ProjectionMatchOptions* search : {&options_.wide_search, &options_.narrow_search}) {
    if (inliers == 0 || inliers >= options_.min_inliers) break;
    const int added = map_.Read([&](const MapData& data) {
      return SearchByProjection(data, local, frame, grid, *pose, *search, &matched);
    });
    if (added > 0) inliers = Optimize(frame, options_.pose, &matched, &*pose);
  }
  stats->best_inliers = std::max(stats->best_inliers, inliers);
  if (inliers < options_.min_inliers) return std::nullopt;
  RelocalizationResult result;
  result.cam_from_world = *pose;
  result.keyframe = candidate;
  result.map_point_ids = std::move(matched.ids);
  result.num_inliers = inliers;
  return result;
}

}  // namespace arucoslam
