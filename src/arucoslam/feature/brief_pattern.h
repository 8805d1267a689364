// BriefPattern: the fixed set of 256 point pairs that rotated BRIEF compares, generated from
// a seed (Gaussian around the patch centre, kept inside the patch) so it is the same everywhere.
#pragma once

#include <array>
#include <cstdint>

namespace arucoslam {

// Largest |offset| (pixels at the keypoint's level) of a pattern point from the centre; a
// rotated, rounded point stays within kBriefPatternRadius + 1 of the centre.
inline constexpr int kBriefPatternRadius = 13;
// Radius of the circular patch used for the orientation (intensity centroid).
inline constexpr int kOrientationPatchRadius = 15;

struct BriefPair {
  float ax, ay, bx, by;  // test: intensity at (ax, ay) < intensity at (bx, by) -> bit = 1
};

struct BriefPattern {
  std::array<BriefPair, 256> pairs{};

  // Deterministic on every platform (own Gaussian sampling on std::mt19937, whose output
  // sequence the standard fixes). Points are drawn with sigma = 31 / 5 px and redrawn until
  // inside kBriefPatternRadius; identical pairs are redrawn.
  static BriefPattern Generate(std::uint32_t seed = 20240531u);
};

}  // namespace arucoslam
