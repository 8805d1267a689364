#include "arucoslam/geometry/two_view.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <random>

#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// Similarity that moves the centroid to the origin and the mean distance to sqrt(2).
Eigen::Matrix3d NormalisingTransform(const Point2dList& points) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  double mean_distance = 0.0;
  for (const Eigen::Vector2d& p : points) mean_distance += (p - centroid).norm();
  mean_distance /= static_cast<double>(points.size());
  const double scale = mean_distance > 1e-12 ? std::sqrt(2.0) / mean_distance : 1.0;
  Eigen::Matrix3d transform;
  transform << scale, 0.0, -scale * centroid.x(), 0.0, scale, -scale * centroid.y(), 0.0, 0.0, 1.0;
  return transform;
}

Point2dList Apply(const Eigen::Matrix3d& transform, const Point2dList& points) {
  Point2dList out;
  out.reserve(points.size());
  for (const Eigen::Vector2d& p : points)
    out.push_back((transform * p.homogeneous()).hnormalized());
  return out;
}

// Unit vector minimising |A x| given A^T A (9x9): the eigenvector of the smallest eigenvalue.
Eigen::Matrix<double, 9, 1> NullVector(const Eigen::Matrix<double, 9, 9>& ata) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> solver(ata);
  return solver.eigenvectors().col(0);
}

Eigen::Matrix3d ToMatrix(const Eigen::Matrix<double, 9, 1>& v) {
  Eigen::Matrix3d m;
  m << v(0), v(1), v(2), v(3), v(4), v(5), v(6), v(7), v(8);
  return m;
}

// `count` distinct indices in [0, n) (partial Fisher-Yates on a reused permutation).
void DrawSample(std::mt19937& rng, int count, std::vector<int>* permutation,
                std::vector<int>* sample) {
  const int n = static_cast<int>(permutation->size());
  sample->clear();
  for (int k = 0; k < count; ++k) {
    const int pick = k + static_cast<int>(rng() % static_cast<std::uint32_t>(n - k));
    std::swap((*permutation)[k], (*permutation)[pick]);
    sample->push_back((*permutation)[k]);
  }
}

template <typename Fit, typename Score>
TwoViewModel Ransac(const Point2dList& points1, const Point2dList& points2, int sample_size,
                    const TwoViewRansacOptions& options, const Fit& fit, const Score& score) {
  TwoViewModel best;
  const int n = static_cast<int>(std::min(points1.size(), points2.size()));
  if (n < sample_size) return best;
  best.valid = true;
  best.score = -1.0;
  std::mt19937 rng(options.seed);
  std::vector<int> permutation(n), sample;
  for (int i = 0; i < n; ++i) permutation[i] = i;
  Point2dList sample1(sample_size), sample2(sample_size);
  std::vector<bool> inliers;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    DrawSample(rng, sample_size, &permutation, &sample);
    for (int k = 0; k < sample_size; ++k) {
      sample1[k] = points1[sample[k]];
      sample2[k] = points2[sample[k]];
    }
    const Eigen::Matrix3d model = fit(sample1, sample2);
    if (!model.allFinite() || model.isZero()) continue;
    const double model_score = score(model, points1, points2, options.sigma, &inliers);
    if (model_score > best.score) {
      best.score = model_score;
      best.matrix = model;
      best.inliers = inliers;
    }
  }
  if (best.score < 0.0) return TwoViewModel{};
  if (options.refine) {
    Point2dList inlier1, inlier2;
    for (int i = 0; i < n; ++i) {
      if (!best.inliers[i]) continue;
      inlier1.push_back(points1[i]);
      inlier2.push_back(points2[i]);
    }
    if (static_cast<int>(inlier1.size()) >= sample_size) {
      const Eigen::Matrix3d refit = fit(inlier1, inlier2);
      const double refit_score = refit.allFinite() && !refit.isZero()
                                     ? score(refit, points1, points2, options.sigma, &inliers)
                                     : -1.0;
      if (refit_score > best.score) {
        best.score = refit_score;
        best.matrix = refit;
        best.inliers = inliers;
      }
    }
  }
  best.num_inliers = static_cast<int>(std::count(best.inliers.begin(), best.inliers.end(), true));
  return best;
}

}  // namespace

Eigen::Matrix3d FundamentalFromPoints(const Point2dList& points1, const Point2dList& points2) {
  if (points1.size() < 8 || points1.size() != points2.size()) return Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d t1 = NormalisingTransform(points1);
  const Eigen::Matrix3d t2 = NormalisingTransform(points2);
  const Point2dList n1 = Apply(t1, points1), n2 = Apply(t2, points2);
  Eigen::Matrix<double, 9, 9> ata = Eigen::Matrix<double, 9, 9>::Zero();
  for (std::size_t i = 0; i < n1.size(); ++i) {
    const double x1 = n1[i].x(), y1 = n1[i].y(), x2 = n2[i].x(), y2 = n2[i].y();
    Eigen::Matrix<double, 9, 1> row;
    row << x2 * x1, x2 * y1, x2, y2 * x1, y2 * y1, y2, x1, y1, 1.0;
    ata.noalias() += row * row.transpose();
  }
  const Eigen::Matrix3d f_full = ToMatrix(NullVector(ata));
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(f_full, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d singular = svd.singularValues();
  singular(2) = 0.0;
  const Eigen::Matrix3d f_rank2 = svd.matrixU() * singular.asDiagonal() * svd.matrixV().transpose();
  const Eigen::Matrix3d fundamental = t2.transpose() * f_rank2 * t1;
  const double norm = fundamental.norm();
  return norm > 0.0 ? Eigen::Matrix3d(fundamental / norm) : fundamental;
}

Eigen::Matrix3d HomographyFromPoints(const Point2dList& points1, const Point2dList& points2) {
  if (points1.size() < 4 || points1.size() != points2.size()) return Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d t1 = NormalisingTransform(points1);
  const Eigen::Matrix3d t2 = NormalisingTransform(points2);
  const Point2dList n1 = Apply(t1, points1), n2 = Apply(t2, points2);
  Eigen::Matrix<double, 9, 9> ata = Eigen::Matrix<double, 9, 9>::Zero();
  for (std::size_t i = 0; i < n1.size(); ++i) {
    const double x1 = n1[i].x(), y1 = n1[i].y(), x2 = n2[i].x(), y2 = n2[i].y();
    Eigen::Matrix<double, 9, 1> row_u, row_v;
    row_u << 0.0, 0.0, 0.0, -x1, -y1, -1.0, y2 * x1, y2 * y1, y2;
    row_v << x1, y1, 1.0, 0.0, 0.0, 0.0, -x2 * x1, -x2 * y1, -x2;
    ata.noalias() += row_u * row_u.transpose() + row_v * row_v.transpose();
  }
  const Eigen::Matrix3d homography = t2.inverse() * ToMatrix(NullVector(ata)) * t1;
  if (std::abs(homography(2, 2)) > 1e-12) return homography / homography(2, 2);
  return homography / homography.norm();
}

double ScoreFundamental(const Eigen::Matrix3d& fundamental, const Point2dList& points1,
                        const Point2dList& points2, double sigma, std::vector<bool>* inliers) {
  const double inverse_sigma2 = 1.0 / (sigma * sigma);
  const std::size_t n = std::min(points1.size(), points2.size());
  inliers->assign(n, false);
  double score = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d x1 = points1[i].homogeneous(), x2 = points2[i].homogeneous();
    const Eigen::Vector3d line2 = fundamental * x1;              // in image 2
    const Eigen::Vector3d line1 = fundamental.transpose() * x2;  // in image 1
    const double n2 = line2.head<2>().squaredNorm(), n1 = line1.head<2>().squaredNorm();
    if (n1 <= 0.0 || n2 <= 0.0) continue;
    const double residual = x2.dot(line2);  // = x1 . line1
    const double chi2_in_2 = residual * residual / n2 * inverse_sigma2;
    const double chi2_in_1 = residual * residual / n1 * inverse_sigma2;
    bool inlier = true;
    if (chi2_in_2 > kChi2OneDof95)
      inlier = false;
    else
      score += kChi2TwoDof95 - chi2_in_2;
    if (chi2_in_1 > kChi2OneDof95)
      inlier = false;
    else
      score += kChi2TwoDof95 - chi2_in_1;
    (*inliers)[i] = inlier;
  }
  return score;
}

double ScoreHomography(const Eigen::Matrix3d& homography, const Point2dList& points1,
                       const Point2dList& points2, double sigma, std::vector<bool>* inliers) {
  const double inverse_sigma2 = 1.0 / (sigma * sigma);
  const std::size_t n = std::min(points1.size(), points2.size());
  inliers->assign(n, false);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(homography);
  if (!lu.isInvertible()) return 0.0;
  const Eigen::Matrix3d inverse = lu.inverse();
  double score = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d in2 = homography * points1[i].homogeneous();
    const Eigen::Vector3d in1 = inverse * points2[i].homogeneous();
    if (std::abs(in2.z()) < 1e-12 || std::abs(in1.z()) < 1e-12) continue;
    const double chi2_in_2 = (in2.hnormalized() - points2[i]).squaredNorm() * inverse_sigma2;
    const double chi2_in_1 = (in1.hnormalized() - points1[i]).squaredNorm() * inverse_sigma2;
    bool inlier = true;
    if (chi2_in_2 > kChi2TwoDof95)
      inlier = false;
    else
      score += kChi2TwoDof95 - chi2_in_2;
    if (chi2_in_1 > kChi2TwoDof95)
      inlier = false;
    else
      score += kChi2TwoDof95 - chi2_in_1;
    (*inliers)[i] = inlier;
  }
  return score;
}

bool TwoViewRansacOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Above("iterations", iterations, 0);
  check.Above("sigma", sigma, 0.0);
  return check.ok();
}

TwoViewModel FindFundamentalRansac(const Point2dList& points1, const Point2dList& points2,
                                   const TwoViewRansacOptions& options) {
  return Ransac(points1, points2, 8, options, FundamentalFromPoints, ScoreFundamental);
}

TwoViewModel FindHomographyRansac(const Point2dList& points1, const Point2dList& points2,
                                  const TwoViewRansacOptions& options) {
  return Ransac(points1, points2, 4, options, HomographyFromPoints, ScoreHomography);
}

Eigen::Matrix3d EssentialFromFundamental(const Eigen::Matrix3d& fundamental,
                                         const Eigen::Matrix3d& k1, const Eigen::Matrix3d& k2) {
  const Eigen::Matrix3d raw = k2.transpose() * fundamental * k1;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(raw, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double sigma = 0.5 * (svd.singularValues()(0) + svd.singularValues()(1));
  return svd.matrixU() * Eigen::Vector3d(sigma, sigma, 0.0).asDiagonal() *
         svd.matrixV().transpose();
}

std::array<Rigid3, 4> DecomposeEssential(const Eigen::Matrix3d& essential) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(essential, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU(), v = svd.matrixV();
  if (u.determinant() < 0.0) u = -u;  // E is defined up to sign: flipping keeps its null space
  if (v.determinant() < 0.0) v = -v;
  Eigen::Matrix3d w;
  w << 0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d r1 = u * w * v.transpose();
  const Eigen::Matrix3d r2 = u * w.transpose() * v.transpose();
  const Eigen::Vector3d t = u.col(2).normalized();
  return {Rigid3(r1, t), Rigid3(r1, -t), Rigid3(r2, t), Rigid3(r2, -t)};
}

std::vector<HomographyMotion> DecomposeHomography(const Eigen::Matrix3d& homography,
                                                  const Eigen::Matrix3d& k1,
                                                  const Eigen::Matrix3d& k2) {
  // In normalised coordinates A = R + t n^T / d up to scale. With A = U diag(d1, d2, d3) V^T
  // and s = det(U) det(V): A' = diag(d1, d2, d3) = d' R' + t' n'^T, R = s U R' V^T, t = U t',
  // n = V n', d = s d', and d' = +-d2 give the two families of solutions.
  const Eigen::Matrix3d a = k2.inverse() * homography * k1;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d u = svd.matrixU(), v = svd.matrixV();
  const double s = u.determinant() * v.determinant();
  const double d1 = svd.singularValues()(0), d2 = svd.singularValues()(1),
               d3 = svd.singularValues()(2);
  std::vector<HomographyMotion> motions;
  if (!(d3 > 0.0) || d1 / d3 < 1.0 + 1e-6) return motions;
  const double x1_abs = std::sqrt((d1 * d1 - d2 * d2) / (d1 * d1 - d3 * d3));
  const double x3_abs = std::sqrt((d2 * d2 - d3 * d3) / (d1 * d1 - d3 * d3));
  const double root = std::sqrt((d1 * d1 - d2 * d2) * (d2 * d2 - d3 * d3));
  for (const double e1 : {1.0, -1.0}) {
    for (const double e3 : {1.0, -1.0}) {
      const double x1 = e1 * x1_abs, x3 = e3 * x3_abs;
      const Eigen::Vector3d normal = (v * Eigen::Vector3d(x1, 0.0, x3)).normalized();
      {  // d' = +d2
        const double sin_theta = e1 * e3 * root / ((d1 + d3) * d2);
        const double cos_theta = (d2 * d2 + d1 * d3) / ((d1 + d3) * d2);
        Eigen::Matrix3d r_prime;
        r_prime << cos_theta, 0.0, -sin_theta, 0.0, 1.0, 0.0, sin_theta, 0.0, cos_theta;
        const Eigen::Vector3d t_prime = (d1 - d3) * Eigen::Vector3d(x1, 0.0, -x3);
        const Eigen::Matrix3d rotation = s * u * r_prime * v.transpose();
        const Eigen::Vector3d translation = u * t_prime / (s * d2);
        motions.push_back({Rigid3(rotation, translation), normal});
      }
      {  // d' = -d2
        const double sin_phi = e1 * e3 * root / ((d1 - d3) * d2);
        const double cos_phi = (d1 * d3 - d2 * d2) / ((d1 - d3) * d2);
        Eigen::Matrix3d r_prime;
        r_prime << cos_phi, 0.0, sin_phi, 0.0, -1.0, 0.0, sin_phi, 0.0, -cos_phi;
        const Eigen::Vector3d t_prime = (d1 + d3) * Eigen::Vector3d(x1, 0.0, x3);
        const Eigen::Matrix3d rotation = s * u * r_prime * v.transpose();
        const Eigen::Vector3d translation = u * t_prime / (-s * d2);
        motions.push_back({Rigid3(rotation, translation), normal});
      }
    }
  }
  return motions;
}

// ---- Relative pose refinement (Sampson errors) ----
double SampsonErrorOfEssential(const Eigen::Matrix3d& e, const Eigen::Vector2d& normalised1,
                               const Eigen::Vector2d& normalised2) {
  const Eigen::Vector3d x1 = normalised1.homogeneous(), x2 = normalised2.homogeneous();
  const Eigen::Vector3d ex1 = e * x1, etx2 = e.transpose() * x2;
  const double denominator = ex1.head<2>().squaredNorm() + etx2.head<2>().squaredNorm();
  if (denominator <= 0.0) return 0.0;
  return x2.dot(ex1) / std::sqrt(denominator);
}

Eigen::Matrix3d EssentialOf(const Rigid3& motion) {
  return Hat(motion.translation) * motion.RotationMatrix();
}

namespace {

using Vector5d = Eigen::Matrix<double, 5, 1>;

// Motion moved by `delta` = [rotation (3); translation direction (2)] in a local chart.
Rigid3 Retract(const Rigid3& motion, const Eigen::Matrix<double, 3, 2>& basis,
               const Vector5d& delta) {
  const Eigen::Quaterniond rotation = ExpSO3(delta.head<3>()) * motion.rotation;
  const Eigen::Vector3d translation = (motion.translation + basis * delta.tail<2>()).normalized();
  return Rigid3(rotation, translation);
}

// Two unit vectors orthogonal to t and to each other.
Eigen::Matrix<double, 3, 2> TangentBasis(const Eigen::Vector3d& t) {
  const Eigen::Vector3d helper =
      std::abs(t.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = t.cross(helper).normalized();
  basis.col(1) = t.cross(basis.col(0)).normalized();
  return basis;
}

Eigen::VectorXd Residuals(const Rigid3& motion, const Point2dList& n1, const Point2dList& n2) {
  const Eigen::Matrix3d e = EssentialOf(motion);
  Eigen::VectorXd r(n1.size());
  for (std::size_t i = 0; i < n1.size(); ++i) r(i) = SampsonErrorOfEssential(e, n1[i], n2[i]);
  return r;
}

}  // namespace

double SampsonError(const Rigid3& cam2_from_cam1, const Eigen::Vector2d& normalised1,
                    const Eigen::Vector2d& normalised2) {
  return SampsonErrorOfEssential(EssentialOf(cam2_from_cam1), normalised1, normalised2);
}

Rigid3 RefineRelativePose(const Rigid3& cam2_from_cam1, const Point2dList& normalised1,
                          const Point2dList& normalised2, const std::vector<bool>& inliers,
                          int iterations) {
  Point2dList n1, n2;
  for (std::size_t i = 0; i < normalised1.size(); ++i) {
    if (!inliers.empty() && !inliers[i]) continue;
    n1.push_back(normalised1[i]);
    n2.push_back(normalised2[i]);
  }
  Rigid3 motion(cam2_from_cam1.rotation, cam2_from_cam1.translation.normalized());
  if (n1.size() < 5 || !motion.translation.allFinite()) return cam2_from_cam1;
  Eigen::VectorXd residuals = Residuals(motion, n1, n2);
  double cost = residuals.squaredNorm();
  double lambda = 1e-4;
  constexpr double kStep = 1e-7;
  for (int iteration = 0; iteration < iterations; ++iteration) {
    const Eigen::Matrix<double, 3, 2> basis = TangentBasis(motion.translation);
    Eigen::MatrixXd jacobian(n1.size(), 5);
    for (int k = 0; k < 5; ++k) {  // central differences: 5 parameters, cheap and exact enough
      Vector5d delta = Vector5d::Zero();
      delta(k) = kStep;
      jacobian.col(k) = (Residuals(Retract(motion, basis, delta), n1, n2) -
                         Residuals(Retract(motion, basis, -delta), n1, n2)) /
                        (2.0 * kStep);
    }
    const Eigen::Matrix<double, 5, 5> jtj = jacobian.transpose() * jacobian;
    const Vector5d jtr = jacobian.transpose() * residuals;
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::Matrix<double, 5, 5> damped = jtj;
      damped.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-12);
      const Vector5d step = damped.ldlt().solve(-jtr);
      const Rigid3 candidate = Retract(motion, basis, step);
      const Eigen::VectorXd candidate_residuals = Residuals(candidate, n1, n2);
      const double candidate_cost = candidate_residuals.squaredNorm();
      if (step.allFinite() && candidate_cost < cost) {
        motion = candidate;
        residuals = candidate_residuals;
        const double relative_decrease = (cost - candidate_cost) / std::max(cost, 1e-300);
        cost = candidate_cost;
        lambda = std::max(lambda * 0.1, 1e-10);
        improved = true;
        if (relative_decrease < 1e-10) return motion;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  return motion;
}

}  // namespace arucoslam
