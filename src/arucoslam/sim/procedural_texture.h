// Procedural textures for the factory world (painted walls, concrete floor, cardboard,
// machine panels, posters), and the seeded random source they use: same seed, same pixels.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

namespace arucoslam {

// Deterministic random numbers on every platform (the standard distributions are not).
class SeededRandom {
 public:
  explicit SeededRandom(std::uint64_t seed) : state_(seed * 0x2545F4914F6CDD1Dull + 0x1234567ull) {}
  std::uint64_t Next();
  double Uniform();                         // [0, 1)
  double Uniform(double low, double high);  // [low, high)
  int Int(int low, int high);               // [low, high], both included
  bool Chance(double probability) { return Uniform() < probability; }
  double Gaussian();  // mean 0, standard deviation 1

 private:
  std::uint64_t state_;
};

// How busy the surfaces look: detail scales contrast of noise, stains and clutter.
enum class TextureLevel { kLow, kMedium, kHigh };
double TextureDetail(TextureLevel level);  // 0.5, 1.0, 1.8

// Smooth noise in [0, 1] (several octaves of bicubic value noise), CV_32FC1,
// feature size `cell_px` pixels for the coarsest octave.
cv::Mat FractalNoise(int width, int height, double cell_px, int octaves, std::uint64_t seed);

// All textures are 8-bit BGR (CV_8UC3). Colours are BGR 0..255.
// A painted wall panel: flat colour with faint noise, stains and drip streaks; an optional
// darker lower band (`band_fraction` of the height, 0 = none) as factories paint them.
cv::Mat PaintedWallTexture(int width, int height, const cv::Scalar& upper_colour,
                           const cv::Scalar& band_colour, double band_fraction, double detail,
                           std::uint64_t seed);
// Sealed concrete: faint mottling, a few cracks, oil stains and tyre marks.
cv::Mat ConcreteFloorTexture(int size, double detail, std::uint64_t seed);
// Ceiling panels with a grid of joints.
cv::Mat CeilingTexture(int size, std::uint64_t seed);
// Corrugated cardboard with tape and a printed shipping label.
cv::Mat CardboardTexture(int size, double detail, std::uint64_t seed);
// Wooden boards (pallets, shelf decks) running along the image width.
cv::Mat WoodTexture(int width, int height, std::uint64_t seed);
// A machine's side: painted metal panels, rivets, a vent grille, a control panel with
// buttons and a display, and hazard stripes at the bottom.
cv::Mat MachinePanelTexture(int width, int height, const cv::Scalar& paint, std::uint64_t seed);
// Yellow and black diagonal stripes.
cv::Mat HazardStripeTexture(int width, int height);
// A distinctive poster or safety sign: coloured shapes, a pictogram and text-like bars.
cv::Mat PosterTexture(int width, int height, std::uint64_t seed);

}  // namespace arucoslam
