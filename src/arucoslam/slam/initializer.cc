#include "arucoslam/slam/initializer.h"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "arucoslam/feature/feature_grid.h"
#include "arucoslam/geometry/triangulation.h"
#include "arucoslam/geometry/two_view.h"
#include "arucoslam/util/median.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;
// Below this parallax a point is "at infinity": its depth sign is not evidence for or
// against a motion, and it is not used as a map point.
constexpr double kInfinityParallaxRad = 0.0063;

// How well one candidate motion explains the inlier correspondences.
struct MotionEvaluation {
  int consistent = 0;       // points in front with small errors, plus points at infinity
  std::vector<int> usable;  // match positions giving good, finite map points
  std::vector<Eigen::Vector3d> points;  // one per usable, in camera 1
  std::vector<double> parallaxes_rad;   // of every consistent point
  int epipolar_support = 0;  // matches within the Sampson gate of the (refined) motion
};

MotionEvaluation EvaluateMotion(const Rigid3& cam2_from_cam1,
                                const std::vector<Eigen::Vector2d>& n1,
                                const std::vector<Eigen::Vector2d>& n2,
                                const std::vector<bool>& inliers, const CameraModel& camera,
                                double max_error_px) {
  const double max_error_sq = max_error_px * max_error_px;
  const Rigid3 cam1_from_cam1;
  MotionEvaluation evaluation;
  for (int i = 0; i < static_cast<int>(n1.size()); ++i) {
    if (!inliers[i]) continue;
    const auto point = TriangulateDlt(cam1_from_cam1, cam2_from_cam1, n1[i], n2[i]);
    if (!point) continue;
    const TriangulationQuality q = EvaluateTriangulation(*point, cam1_from_cam1, cam2_from_cam1,
                                                         n1[i], n2[i], camera.fx, camera.fy);
    const bool at_infinity = q.parallax_rad < kInfinityParallaxRad;
    if (at_infinity) {
      // Depth sign is noise here; judge the rays: camera-1 ray turned into camera 2.
      const Eigen::Vector3d ray = cam2_from_cam1.rotation * n1[i].homogeneous();
      if (ray.z() <= 0.0) continue;
      const Eigen::Vector2d d = ray.hnormalized() - n2[i];
      if (camera.fx * camera.fx * d.x() * d.x() + camera.fy * camera.fy * d.y() * d.y() >
          max_error_sq) {
        continue;
      }
    } else if (q.depth1 <= 0.0 || q.depth2 <= 0.0 || q.error1_sq_px > max_error_sq ||
               q.error2_sq_px > max_error_sq) {
      continue;
    }
    ++evaluation.consistent;
    evaluation.parallaxes_rad.push_back(at_infinity ? 0.0 : q.parallax_rad);
    if (!at_infinity) {
      evaluation.usable.push_back(i);
      evaluation.points.push_back(*point);
    }
  }
  return evaluation;
}

// Median pixel distance between the points of image 2 and those of image 1 turned by the
// rotation that best aligns their viewing rays (Kabsch on unit bearings).
double DerotatedMedianFlow(const std::vector<Eigen::Vector2d>& n1,
                           const std::vector<Eigen::Vector2d>& n2, const std::vector<bool>& inliers,
                           const CameraModel& camera) {
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n1.size(); ++i) {
    if (!inliers[i]) continue;
    correlation += n2[i].homogeneous().normalized() * n1[i].homogeneous().normalized().transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d rotation = svd.matrixU() * fix * svd.matrixV().transpose();
  std::vector<double> flows;
  for (std::size_t i = 0; i < n1.size(); ++i) {
    if (!inliers[i]) continue;
    const Eigen::Vector3d turned = rotation * n1[i].homogeneous();
    if (turned.z() <= 0.0) continue;
    const Eigen::Vector2d d = turned.hnormalized() - n2[i];
    flows.push_back(std::hypot(camera.fx * d.x(), camera.fy * d.y()));
  }
  return Median(flows);
}

InitializationResult Fail(InitializationResult result, InitFailure failure, std::string message) {
  result.success = false;
  result.failure = failure;
  result.message = std::move(message);
  return result;
}

}  // namespace

bool InitializerOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("min_matches", min_matches, 8);
  check.Nested("matching", matching);
  check.Above("ransac_iterations", ransac_iterations, 0);
  check.Above("sigma_px", sigma_px, 0.0);
  check.InRange("homography_share", homography_share, 0.0, 1.0, Interval::kOpen);
  check.AtLeast("min_median_flow_px", min_median_flow_px, 0.0);
  check.AtLeast("min_translation_flow_px", min_translation_flow_px, 0.0);
  check.AtLeast("min_parallax_deg", min_parallax_deg, 0.0);
  check.Above("max_reprojection_px", max_reprojection_px, 0.0);
  check.AtLeast("min_triangulated", min_triangulated, 1);
  check.InRange("min_triangulated_fraction", min_triangulated_fraction, 0.0, 1.0,
                Interval::kClosed);
  check.Above("relax_after_s", relax_after_s, 0.0);
  check.InRange("relaxed_triangulated_fraction", relaxed_triangulated_fraction, 0.0, 1.0,
                Interval::kClosed);
  check.InRange("ambiguity_ratio", ambiguity_ratio, 0.0, 1.0, Interval::kOpen);
  check.InRange("min_epipolar_support_ratio", min_epipolar_support_ratio, 0.0, 1.0,
                Interval::kClosed);
  check.InRange("min_axis_agreement_cos", min_axis_agreement_cos, 0.0, 1.0, Interval::kClosed);
  return check.ok();
}

std::string InitFailureName(InitFailure failure) {
  switch (failure) {
    case InitFailure::kNone:
      return "none";
    case InitFailure::kTooFewMatches:
      return "too few matches";
    case InitFailure::kTooLittleParallax:
      return "too little parallax";
    case InitFailure::kPureRotation:
      return "pure rotation";
    case InitFailure::kAmbiguous:
      return "ambiguous";
    case InitFailure::kTooFewTriangulated:
      return "too few triangulated points";
  }
  return "unknown";
}

Initializer::Initializer(const InitializerOptions& options) : options_(options) {
  if (!options_.Check()) throw std::invalid_argument("InitializerOptions: invalid values");
}

InitializationResult Initializer::Initialize(const OrbFeatures& frame1, const OrbFeatures& frame2,
                                             const CameraModel& camera) const {
  if (frame1.undistorted.size() != frame1.size() || frame2.undistorted.size() != frame2.size()) {
    throw std::invalid_argument("Initializer::Initialize: features must be undistorted first");
  }
  const FeatureGrid grid2(frame2);
  std::vector<Eigen::Vector2d> predicted;
  predicted.reserve(frame1.size());
  for (const cv::KeyPoint& kp : frame1.keypoints) predicted.emplace_back(kp.pt.x, kp.pt.y);
  const std::vector<FeatureMatch> matches =
      MatchInWindow(frame1, frame2, grid2, predicted, options_.matching);
  return InitializeFromMatches(frame1.undistorted, frame2.undistorted, matches, camera);
}

namespace {

// Candidate motions of the chosen model (unit-free translations).
std::vector<Rigid3> CandidateMotions(TwoViewModelKind kind, const Eigen::Matrix3d& matrix,
                                     const Eigen::Matrix3d& k) {
  std::vector<Rigid3> motions;
  if (kind == TwoViewModelKind::kHomography) {
    for (const HomographyMotion& m : DecomposeHomography(matrix, k, k)) {
      motions.push_back(m.cam2_from_cam1);
    }
  } else {
    const std::array<Rigid3, 4> four = DecomposeEssential(EssentialFromFundamental(matrix, k, k));
    motions.assign(four.begin(), four.end());
  }
  return motions;
}

// Refines the motion on the model inliers, then re-selects the inliers among ALL matches by
// their Sampson error under the refined motion (the linear model's bias wrongly rejects
// points at the image border and keeps a few outliers) and refines again on those.
Rigid3 RefineWithSampsonGate(const Rigid3& motion, const std::vector<Eigen::Vector2d>& n1,
                             const std::vector<Eigen::Vector2d>& n2,
                             const std::vector<bool>& inliers, const CameraModel& camera,
                             double sigma_px, std::vector<bool>* gated) {
  const double focal = 0.5 * (camera.fx + camera.fy);
  const double gate = std::sqrt(kChi2OneDof95) * sigma_px / focal;
  Rigid3 refined = RefineRelativePose(motion, n1, n2, inliers);
  for (int round = 0; round < 2; ++round) {
    gated->assign(n1.size(), false);
    for (std::size_t i = 0; i < n1.size(); ++i) {
      (*gated)[i] = std::abs(SampsonError(refined, n1[i], n2[i])) <= gate;
    }
    refined = RefineRelativePose(refined, n1, n2, *gated);
  }
  return refined;
}

// Tests every motion of the chosen model by triangulation and keeps the best if it is
// unambiguous, well supported and has enough parallax; scales it to median depth 1.
InitializationResult ChooseMotion(const InitializerOptions& options, InitializationResult result,
                                  const TwoViewModel& model, const std::vector<bool>& judged,
                                  const std::vector<bool>& off_plane,
                                  const std::vector<Eigen::Vector2d>& n1,
                                  const std::vector<Eigen::Vector2d>& n2,
                                  const std::vector<FeatureMatch>& matches,
                                  const CameraModel& camera, const Eigen::Matrix3d& k) {
  const TwoViewModelKind kind = result.model;
  const std::vector<Rigid3> candidates = CandidateMotions(kind, model.matrix, k);
  if (candidates.empty()) {
    return Fail(std::move(result), InitFailure::kPureRotation,
                "homography has no translation solution");
  }
  // Each candidate that explains points is sharpened by a few Sampson iterations (the linear
  // model is biased by noise; kept unless it then explains clearly fewer points), and its
  // epipolar support among the matches off the plane is counted. Counting points in front of
  // both cameras alone favours a plane's twin motion (translation along the plane's normal)
  // over a forward motion, whose epipole in the image lets noise flip the depth of many
  // points; the matches off the plane follow only the true motion's epipolar lines.
  std::vector<Rigid3> motions = candidates;
  std::vector<MotionEvaluation> evaluations;
  int max_support = 0;
  for (Rigid3& motion : motions) {
    evaluations.push_back(
        EvaluateMotion(motion, n1, n2, judged, camera, options.max_reprojection_px));
    if (evaluations.back().consistent == 0) continue;
    std::vector<bool> refined_inliers;
    const Rigid3 refined = RefineWithSampsonGate(motion, n1, n2, model.inliers, camera,
                                                 options.sigma_px, &refined_inliers);
    MotionEvaluation refined_evaluation =
        EvaluateMotion(refined, n1, n2, refined_inliers, camera, options.max_reprojection_px);
    for (std::size_t i = 0; i < off_plane.size(); ++i) {
      if (off_plane[i] && refined_inliers[i]) ++refined_evaluation.epipolar_support;
    }
    if (refined_evaluation.consistent >= 0.95 * evaluations.back().consistent) {
      motion = refined;
      evaluations.back() = std::move(refined_evaluation);
    } else {
      evaluations.back().epipolar_support = refined_evaluation.epipolar_support;
    }
    max_support = std::max(max_support, evaluations.back().epipolar_support);
  }
  // With enough matches off the homography's plane, the candidate that best explains their
  // epipolar geometry sets the translation axis. Another candidate about as well supported
  // along a different axis (the plane's twin while the baseline is short) makes the pair
  // ambiguous: later frames will tell them apart. A plane alone cannot: there cheirality
  // decides, as for the fundamental model's four motions.
  const bool judge_axis =
      std::count(off_plane.begin(), off_plane.end(), true) >= options.min_triangulated;
  int best_supported = -1;
  for (std::size_t c = 0; c < evaluations.size(); ++c) {
    if (evaluations[c].consistent == 0) continue;
    if (best_supported < 0 ||
        evaluations[c].epipolar_support > evaluations[best_supported].epipolar_support) {
      best_supported = static_cast<int>(c);
    }
  }
  if (best_supported < 0) {
    return Fail(std::move(result), InitFailure::kTooFewTriangulated,
                "no motion places points in front of both cameras");
  }
  const Eigen::Vector3d axis = motions[best_supported].translation.normalized();
  int best = -1;
  int second_consistent = 0;
  for (std::size_t c = 0; c < evaluations.size(); ++c) {
    const MotionEvaluation& evaluation = evaluations[c];
    if (evaluation.consistent == 0) continue;
    if (judge_axis &&
        evaluation.epipolar_support < options.min_epipolar_support_ratio * max_support) {
      continue;
    }
    if (judge_axis &&
        std::abs(motions[c].translation.normalized().dot(axis)) < options.min_axis_agreement_cos) {
      return Fail(std::move(result), InitFailure::kAmbiguous,
                  fmt::format("two translation axes fit the epipolar geometry ({} and {} "
                              "matches)",
                              evaluations[best_supported].epipolar_support,
                              evaluation.epipolar_support));
    }
    if (best < 0 || evaluation.consistent > evaluations[best].consistent) {
      if (best >= 0) second_consistent = evaluations[best].consistent;
      best = static_cast<int>(c);
    } else {
      second_consistent = std::max(second_consistent, evaluation.consistent);
    }
  }
  const Rigid3 motion = motions[best];
  MotionEvaluation& chosen = evaluations[best];
  std::vector<double> parallaxes_deg;
  for (double p : chosen.parallaxes_rad) parallaxes_deg.push_back(p * kDegPerRad);
  result.median_parallax_deg = Median(parallaxes_deg);
  // The parallax of the min_triangulated-th widest point: far points (a street ahead of a car)
  // keep the median near zero however wide the baseline, while the nearer points that hold
  // the map's geometry already see it from well-separated views.
  std::vector<double> widest_first = parallaxes_deg;
  std::sort(widest_first.begin(), widest_first.end(), std::greater<double>());
  const std::size_t rank = static_cast<std::size_t>(options.min_triangulated) - 1;
  const double parallax_deg =
      widest_first.empty() ? 0.0 : widest_first[std::min(rank, widest_first.size() - 1)];
  const std::string summary = fmt::format(
      "{} model, {} inliers, best motion {} consistent, second {}, median parallax "
      "{:.2f} deg, {}th widest {:.2f} deg",
      kind == TwoViewModelKind::kHomography ? "H" : "F", model.num_inliers, chosen.consistent,
      second_consistent, result.median_parallax_deg, options.min_triangulated, parallax_deg);
  if (second_consistent > options.ambiguity_ratio * chosen.consistent) {
    return Fail(std::move(result), InitFailure::kAmbiguous, summary);
  }
  const double needed = std::max<double>(options.min_triangulated,
                                         options.min_triangulated_fraction * model.num_inliers);
  if (chosen.consistent < needed) {
    return Fail(std::move(result), InitFailure::kTooFewTriangulated, summary);
  }
  if (parallax_deg < options.min_parallax_deg) {
    return Fail(std::move(result), InitFailure::kTooLittleParallax, summary);
  }
  if (static_cast<int>(chosen.usable.size()) < options.min_triangulated) {
    return Fail(std::move(result), InitFailure::kTooFewTriangulated, summary);
  }
  result.success = true;
  result.message = summary;
  result.cam2_from_cam1 = motion;
  for (std::size_t u = 0; u < chosen.usable.size(); ++u) {
    result.matches.push_back(matches[chosen.usable[u]]);
    result.points_in_cam1.push_back(chosen.points[u]);
  }
  ScaleToUnitMedianDepth(&result);
  return result;
}

}  // namespace

void ScaleToUnitMedianDepth(InitializationResult* result) {
  if (result->points_in_cam1.empty()) return;
  std::vector<double> depths;
  for (const Eigen::Vector3d& point : result->points_in_cam1) depths.push_back(point.z());
  const double scale = 1.0 / Median(depths);
  result->cam2_from_cam1.translation *= scale;
  for (Eigen::Vector3d& point : result->points_in_cam1) point *= scale;
}

InitializationResult Initializer::InitializeFromMatches(
    const std::vector<Eigen::Vector2d>& normalised1,
    const std::vector<Eigen::Vector2d>& normalised2, const std::vector<FeatureMatch>& matches,
    const CameraModel& camera) const {
  InitializationResult result;
  result.num_matches = static_cast<int>(matches.size());
  if (result.num_matches < options_.min_matches) {
    return Fail(result, InitFailure::kTooFewMatches,
                fmt::format("{} matches, {} needed", result.num_matches, options_.min_matches));
  }
  Eigen::Matrix3d k;
  k << camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0;
  std::vector<Eigen::Vector2d> n1, n2;
  Point2dList px1, px2;
  std::vector<double> flows;
  for (const FeatureMatch& m : matches) {
    n1.push_back(normalised1.at(m.index1));
    n2.push_back(normalised2.at(m.index2));
    px1.push_back((k * n1.back().homogeneous()).hnormalized());
    px2.push_back((k * n2.back().homogeneous()).hnormalized());
    flows.push_back((px2.back() - px1.back()).norm());
  }
  result.median_flow_px = Median(flows);
  if (result.median_flow_px < options_.min_median_flow_px) {
    return Fail(result, InitFailure::kTooLittleParallax,
                fmt::format("median flow {:.2f} px: camera static", result.median_flow_px));
  }
  TwoViewRansacOptions ransac;
  ransac.iterations = options_.ransac_iterations;
  ransac.sigma = options_.sigma_px;
  ransac.seed = options_.seed;
  const TwoViewModel homography = FindHomographyRansac(px1, px2, ransac);
  ransac.seed = options_.seed + 1;
  const TwoViewModel fundamental = FindFundamentalRansac(px1, px2, ransac);
  const double total = homography.score + fundamental.score;
  result.homography_share = total > 0.0 ? homography.score / total : 0.0;
  const bool use_h = homography.valid && result.homography_share > options_.homography_share;
  result.model = use_h ? TwoViewModelKind::kHomography : TwoViewModelKind::kFundamental;
  const TwoViewModel& chosen = use_h ? homography : fundamental;
  if (!chosen.valid || chosen.num_inliers < options_.min_triangulated) {
    return Fail(result, InitFailure::kTooFewTriangulated,
                fmt::format("{} model inliers", chosen.num_inliers));
  }
  const double derotated = DerotatedMedianFlow(n1, n2, chosen.inliers, camera);
  if (derotated < options_.min_translation_flow_px) {
    return Fail(result, InitFailure::kPureRotation,
                fmt::format("median flow {:.2f} px, {:.2f} px after removing the rotation",
                            result.median_flow_px, derotated));
  }
  // The candidate motions are judged on every match either model explains; the matches of
  // the fundamental model off the homography's plane tell a plane's two motions apart.
  std::vector<bool> judged = chosen.inliers;
  std::vector<bool> off_plane(judged.size(), false);
  if (use_h && fundamental.valid) {
    for (std::size_t i = 0; i < judged.size(); ++i) {
      off_plane[i] = fundamental.inliers[i] && !homography.inliers[i];
      judged[i] = judged[i] || fundamental.inliers[i];
    }
  }
  return ChooseMotion(options_, std::move(result), chosen, judged, off_plane, n1, n2, matches,
                      camera, k);
}

}  // namespace arucoslam

