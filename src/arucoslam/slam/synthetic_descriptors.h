// Descriptors for the synthetic scenes of the slam/ tests: a random one per scene point, and
// the bit flips that make each observation of it differ a little.
#pragma once

#include <cstdint>
#include <random>

#include "arucoslam/map/map_point.h"

namespace arucoslam {

// 32 random bytes, one draw of `random` per byte.
inline OrbDescriptor RandomOrbDescriptor(std::mt19937& random) {
  OrbDescriptor descriptor;
  for (auto& byte : descriptor) byte = static_cast<std::uint8_t>(random() & 0xff);
  return descriptor;
}

// Flips `count` bits of `descriptor` drawn at random (one draw each; a bit may flip twice).
inline void FlipRandomBits(int count, std::mt19937& random, OrbDescriptor* descriptor) {
  for (int flip = 0; flip < count; ++flip) {
    const int bit = static_cast<int>(random() % 256);
    (*descriptor)[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
  }
}

}  // namespace arucoslam
