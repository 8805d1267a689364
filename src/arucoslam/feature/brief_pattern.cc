#include "arucoslam/feature/brief_pattern.h"

#include <cmath>
#include <random>

namespace arucoslam {
namespace {

// Uniform in (0, 1) from the raw 32-bit output (never 0, so the logarithm is finite).
double Uniform01(std::mt19937& rng) { return (static_cast<double>(rng()) + 0.5) / 4294967296.0; }

// One Gaussian offset (Box-Muller), redrawn until inside the pattern radius.
void DrawPoint(std::mt19937& rng, double sigma, float* x, float* y) {
  constexpr double kTwoPi = 6.283185307179586;
  while (true) {
    const double radius = sigma * std::sqrt(-2.0 * std::log(Uniform01(rng)));
    const double angle = kTwoPi * Uniform01(rng);
    const double px = std::round(radius * std::cos(angle));
    const double py = std::round(radius * std::sin(angle));
    if (px * px + py * py <= kBriefPatternRadius * kBriefPatternRadius) {
      *x = static_cast<float>(px);
      *y = static_cast<float>(py);
      return;
    }
  }
}

}  // namespace

BriefPattern BriefPattern::Generate(std::uint32_t seed) {
  constexpr double kSigma = 31.0 / 5.0;
  std::mt19937 rng(seed);
  BriefPattern pattern;
  for (BriefPair& pair : pattern.pairs) {
    do {
      DrawPoint(rng, kSigma, &pair.ax, &pair.ay);
      DrawPoint(rng, kSigma, &pair.bx, &pair.by);
    } while (pair.ax == pair.bx && pair.ay == pair.by);
  }
  return pattern;
}

}  // namespace arucoslam
