// Umeyama (1991) least-squares alignment of corresponding point sets: the similarity
// (or rigid transform) `target_from_source` minimising sum |target_i - T * source_i|^2.
#pragma once

#include <optional>
#include <vector>

#include "arucoslam/geometry/sim3.h"

namespace arucoslam {

enum class AlignmentKind { kRigid, kSimilarity };

// Returns nullopt when fewer than 3 pairs are given, the sizes differ, the source points
// are degenerate (all coincident), or (kSimilarity) the target points are all coincident.
// Collinear points fit with an arbitrary rotation about their line (same residual).
// With kRigid the returned scale is exactly 1.
std::optional<Sim3> UmeyamaAlignment(const std::vector<Eigen::Vector3d>& source,
                                     const std::vector<Eigen::Vector3d>& target,
                                     AlignmentKind kind);

}  // namespace arucoslam
