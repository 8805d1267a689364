// Absolute and relative pose errors with evo's definitions: APE compares aligned poses one
// by one, RPE compares motions E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) over index pairs (i, j).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "arucoslam/io/trajectory_io.h"

namespace arucoslam {

// Which scalar is taken from an error pose E.
enum class PoseRelation {
  kTranslation,         // |t(E)|, metres
  kRotationAngleDeg,    // rotation angle of E, degrees
  kRotationAngleRad,    // rotation angle of E, radians
  kFullTransformation,  // Frobenius norm of E - I (4x4), unitless
};
std::string PoseRelationName(PoseRelation relation);  // evo's wording, e.g. "translation part"

// Per pose i: the error of est.poses[i] against gt.poses[i] (E = P_i^-1 Q_i; for
// kTranslation the position difference). Sizes must match.
std::vector<double> AbsolutePoseErrors(const Trajectory& gt, const Trajectory& est,
                                       PoseRelation relation);

enum class DeltaUnit { kFrames, kSeconds, kMeters };
std::string DeltaUnitName(DeltaUnit unit);  // "frames", "s", "m"

struct RelativeErrorOptions {
  double delta = 1.0;  // in `unit` (frames: a positive integer)
  DeltaUnit unit = DeltaUnit::kFrames;
  bool all_pairs = false;           // every pair at distance delta instead of consecutive ones
  double relative_tolerance = 0.1;  // all_pairs with metres/seconds: accept |d - delta| <=
                                    // tolerance * delta

  bool Check(std::string* why = nullptr) const;
};

using IndexPairs = std::vector<std::pair<std::size_t, std::size_t>>;

// Index pairs on the estimate, as evo's `id_pairs_from_delta` chooses them:
//  frames, consecutive: (0, d), (d, 2d), ...; all pairs: (i, i + d);
//  metres, consecutive: the poses where the travelled path since the previous chosen pose
//          reaches delta (the first one included), paired one after the other; all pairs:
//          for each i the j > i whose path length from i is closest to delta, if within
//          tolerance;
//  seconds: the same as metres with time instead of path length.
IndexPairs RelativeIndexPairs(const Trajectory& est, const RelativeErrorOptions& options);

// Errors of the motions over `pairs` (indices into both trajectories). The translation part
// uses Trajectory::RotationMatrix (a KITTI file's raw matrices), as evo does.
std::vector<double> RelativePoseErrors(const Trajectory& gt, const Trajectory& est,
                                       const IndexPairs& pairs, PoseRelation relation);

}  // namespace arucoslam
