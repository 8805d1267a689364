// Two-view geometry between corresponding image points: normalised 8-point fundamental and
// DLT homography in RANSAC with chi-square scoring, essential from F and K, and the
// decomposition of E and H into candidate motions cam2_from_cam1.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

using Point2dList = std::vector<Eigen::Vector2d>;

// Chi-square values at 95% for 1 and 2 degrees of freedom.
inline constexpr double kChi2OneDof95 = 3.841;
inline constexpr double kChi2TwoDof95 = 5.991;

// x2^T F x1 = 0 from >= 8 correspondences (Hartley-normalised linear solution, rank 2
// enforced). Points in any consistent units (pixels usually). Zero matrix if fewer points.
Eigen::Matrix3d FundamentalFromPoints(const Point2dList& points1, const Point2dList& points2);

// x2 ~ H x1 from >= 4 correspondences (Hartley-normalised DLT). Zero matrix if fewer points.
Eigen::Matrix3d HomographyFromPoints(const Point2dList& points1, const Point2dList& points2);

// Score of a model over all correspondences, ORB-SLAM style: each direction whose squared
// error / sigma^2 stays under the rejection threshold (F: point-to-epipolar-line distance,
// 1 dof, 3.841; H: transfer error, 2 dof, 5.991) adds 5.991 - error, so both models' scores
// are in the same currency. A correspondence is an inlier when both directions pass.
double ScoreFundamental(const Eigen::Matrix3d& fundamental, const Point2dList& points1,
                        const Point2dList& points2, double sigma, std::vector<bool>* inliers);
double ScoreHomography(const Eigen::Matrix3d& homography, const Point2dList& points1,
                       const Point2dList& points2, double sigma, std::vector<bool>* inliers);

struct TwoViewRansacOptions {
  int iterations = 200;         // minimal samples drawn (fixed count: deterministic runtime)
  double sigma = 1.0;           // measurement noise, units of the points (pixels)
  std::uint32_t seed = 0x5eed;  // random generator seed (same seed -> same result)
  bool refine = true;           // refit on all inliers and keep the refit if it scores higher
  bool Check(std::string* why = nullptr) const;
};

struct TwoViewModel {
  bool valid = false;  // false when there were too few points
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Zero();
  double score = 0.0;
  std::vector<bool> inliers;
  int num_inliers = 0;
};

TwoViewModel FindFundamentalRansac(const Point2dList& points1, const Point2dList& points2,
                                   const TwoViewRansacOptions& options = {});
TwoViewModel FindHomographyRansac(const Point2dList& points1, const Point2dList& points2,
                                  const TwoViewRansacOptions& options = {});

// E = K2^T F K1, projected to the essential manifold (two equal singular values, one zero).
Eigen::Matrix3d EssentialFromFundamental(const Eigen::Matrix3d& fundamental,
                                         const Eigen::Matrix3d& k1, const Eigen::Matrix3d& k2);

// The four motions cam2_from_cam1 compatible with E (translation of unit length); exactly one
// puts the scene in front of both cameras.
std::array<Rigid3, 4> DecomposeEssential(const Eigen::Matrix3d& essential);

struct HomographyMotion {
  Rigid3 cam2_from_cam1;  // translation in units of the plane distance from camera 1
  Eigen::Vector3d normal_in_cam1 = Eigen::Vector3d::UnitZ();  // plane normal n: n^T X1 = d
};

// Candidate motions for a homography between pixel points of cameras K1 and K2 (SVD method
// of Faugeras & Lustman): 8 candidates in general, empty when the singular values coincide
// (pure rotation or no motion: no translation can be recovered).
std::vector<HomographyMotion> DecomposeHomography(const Eigen::Matrix3d& homography,
                                                  const Eigen::Matrix3d& k1,
                                                  const Eigen::Matrix3d& k2);

// The essential matrix [t]x R of a motion cam2_from_cam1 = (R, t).
Eigen::Matrix3d EssentialOf(const Rigid3& motion);
// Signed Sampson error (normalised units) of x2^T E x1 = 0 for one correspondence; 0 where
// it is undefined (both epipolar lines degenerate).
double SampsonErrorOfEssential(const Eigen::Matrix3d& e, const Eigen::Vector2d& normalised1,
                               const Eigen::Vector2d& normalised2);
// Sampson error (normalised units) of x2^T [t]x R x1 = 0 for one correspondence.
double SampsonError(const Rigid3& cam2_from_cam1, const Eigen::Vector2d& normalised1,
                    const Eigen::Vector2d& normalised2);

// Levenberg-Marquardt on the 5 degrees of freedom of a calibrated relative pose (rotation,
// translation direction) minimising the Sampson errors of the correspondences flagged in
// `inliers` (all when empty). Returns the refined motion with a unit translation; the input
// when there are fewer than 5 correspondences.
Rigid3 RefineRelativePose(const Rigid3& cam2_from_cam1, const Point2dList& normalised1,
                          const Point2dList& normalised2, const std::vector<bool>& inliers,
                          int iterations = 10);

}  // namespace arucoslam
