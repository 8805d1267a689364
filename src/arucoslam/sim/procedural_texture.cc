#include "arucoslam/sim/procedural_texture.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

namespace arucoslam {

std::uint64_t SeededRandom::Next() {
  std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double SeededRandom::Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }

double SeededRandom::Uniform(double low, double high) { return low + (high - low) * Uniform(); }

int SeededRandom::Int(int low, int high) {
  const auto span = static_cast<std::uint64_t>(high - low + 1);
  return low + static_cast<int>(Next() % span);
}

double SeededRandom::Gaussian() {
  const double u = std::max(Uniform(), 1e-300);
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * std::numbers::pi * Uniform());
}

double TextureDetail(TextureLevel level) {
  switch (level) {
    case TextureLevel::kLow:
      return 0.5;
    case TextureLevel::kMedium:
      return 1.0;
    case TextureLevel::kHigh:
      return 1.8;
  }
  return 1.0;
}

namespace {

cv::Scalar Scale(const cv::Scalar& colour, double factor) {
  return cv::Scalar(colour[0] * factor, colour[1] * factor, colour[2] * factor);
}

// image *= (1 + amount * (2 * noise - 1)), channel-wise, noise in [0, 1].
void Modulate(cv::Mat& image, const cv::Mat& noise, double amount) {
  cv::Mat gain = 1.0 + amount * (2.0 * noise - 1.0);
  cv::Mat gain3;
  cv::merge(std::vector<cv::Mat>{gain, gain, gain}, gain3);
  cv::Mat as_float;
  image.convertTo(as_float, CV_32FC3);
  cv::multiply(as_float, gain3, as_float);
  as_float.convertTo(image, CV_8UC3);
}

// Darkens (factor < 1) or lightens the image where `mask` (CV_32F, 0..1) is set.
void Shade(cv::Mat& image, const cv::Mat& mask, double factor) {
  cv::Mat noise = 0.5 + mask * ((factor - 1.0) / 2.0);
  Modulate(image, noise, 1.0);
}

// Soft blobs (stains) of random size; returns a CV_32F mask 0..1.
cv::Mat BlobMask(int width, int height, int count, double min_radius, double max_radius,
                 SeededRandom& random) {
  cv::Mat mask = cv::Mat::zeros(height, width, CV_32FC1);
  for (int i = 0; i < count; ++i) {
    const cv::Point centre(random.Int(0, width - 1), random.Int(0, height - 1));
    const cv::Size axes(static_cast<int>(random.Uniform(min_radius, max_radius)),
                        static_cast<int>(random.Uniform(min_radius, max_radius) * 0.6));
    cv::ellipse(mask, centre, axes, random.Uniform(0, 180), 0, 360, random.Uniform(0.4, 1.0),
                cv::FILLED, cv::LINE_AA);
  }
  const int k = static_cast<int>(max_radius) | 1;
  cv::GaussianBlur(mask, mask, cv::Size(k, k), 0);
  return mask;
}

// A crack: a jittered random walk of thin dark segments.
void DrawCrack(cv::Mat& image, SeededRandom& random, double strength) {
  cv::Point2d point(random.Uniform(0, image.cols), random.Uniform(0, image.rows));
  double angle = random.Uniform(0, 2 * std::numbers::pi);
  const int steps = random.Int(8, 30);
  const cv::Scalar colour = Scale(cv::Scalar(80, 80, 80), 1.0 - 0.2 * strength);
  for (int i = 0; i < steps; ++i) {
    angle += random.Uniform(-0.6, 0.6);
    const cv::Point2d next = point + 12.0 * cv::Point2d(std::cos(angle), std::sin(angle));
    cv::line(image, point, next, colour, 1, cv::LINE_AA);
    point = next;
  }
}

// Text-like bars (lines of "words") in a rectangle.
void DrawTextBars(cv::Mat& image, cv::Rect area, int lines, const cv::Scalar& colour,
                  SeededRandom& random) {
  const int line_height = std::max(2, area.height / std::max(1, 2 * lines));
  for (int line = 0; line < lines; ++line) {
    int x = area.x;
    const int y = area.y + line * 2 * line_height;
    const int end = area.x + static_cast<int>(area.width * random.Uniform(0.5, 1.0));
    while (x < end) {
      const int word = random.Int(line_height, 4 * line_height);
      cv::rectangle(image, cv::Rect(x, y, std::min(word, end - x), line_height), colour,
                    cv::FILLED);
      x += word + line_height;
    }
  }
}

}  // namespace

cv::Mat FractalNoise(int width, int height, double cell_px, int octaves, std::uint64_t seed) {
  SeededRandom random(seed);
  cv::Mat sum = cv::Mat::zeros(height, width, CV_32FC1);
  double amplitude = 1.0, total = 0.0, cell = cell_px;
  for (int octave = 0; octave < octaves; ++octave) {
    const int grid_w = std::max(2, static_cast<int>(std::ceil(width / cell)) + 1);
    const int grid_h = std::max(2, static_cast<int>(std::ceil(height / cell)) + 1);
    cv::Mat grid(grid_h, grid_w, CV_32FC1);
    for (int r = 0; r < grid_h; ++r) {
      for (int c = 0; c < grid_w; ++c) grid.at<float>(r, c) = static_cast<float>(random.Uniform());
    }
    cv::Mat layer;
    cv::resize(grid, layer, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
    sum += amplitude * layer;
    total += amplitude;
    amplitude *= 0.5;
    cell = std::max(1.0, cell / 2.0);
  }
  sum /= total;
  cv::min(cv::max(sum, 0.0), 1.0, sum);
  return sum;
}

cv::Mat PaintedWallTexture(int width, int height, const cv::Scalar& upper_colour,
                           const cv::Scalar& band_colour, double band_fraction, double detail,
                           std::uint64_t seed) {
  SeededRandom random(seed);
  cv::Mat image(height, width, CV_8UC3, upper_colour);
  const int band_top = static_cast<int>(height * (1.0 - band_fraction));
  if (band_fraction > 0.0) {
    cv::rectangle(image, cv::Rect(0, band_top, width, height - band_top), band_colour, cv::FILLED);
    cv::line(image, {0, band_top}, {width, band_top}, Scale(band_colour, 0.6), 3);
  }
  Modulate(image, FractalNoise(width, height, width / 3.0, 6, random.Next()), 0.035 * detail);
  Shade(image,
        BlobMask(width, height, random.Int(1, 3 + static_cast<int>(3 * detail)), width * 0.04,
                 width * 0.16, random),
        1.0 - 0.12 * detail);
  // Drip streaks from the top and scuffs near the floor, where trolleys rub the paint.
  cv::Mat marks = cv::Mat::zeros(height, width, CV_32FC1);
  for (int i = random.Int(2, 6); i > 0; --i) {
    const int x = random.Int(0, width - 1);
    cv::line(marks, {x, 0}, {x + random.Int(-6, 6), random.Int(height / 8, height / 2)},
             random.Uniform(0.3, 1.0), random.Int(2, 5));
  }
  for (int i = static_cast<int>(random.Uniform(2, 8) * detail); i > 0; --i) {
    const int x = random.Int(0, width - 1);
    const int y = height - 1 - random.Int(height / 40, height / 6);
    cv::line(marks, {x, y}, {x + random.Int(10, width / 6), y + random.Int(-4, 4)},
             random.Uniform(0.5, 1.0), random.Int(1, 4), cv::LINE_AA);
  }
  cv::GaussianBlur(marks, marks, cv::Size(5, 5), 0);
  Shade(image, marks, 1.0 - 0.25 * std::min(detail, 1.5));
  return image;
}

cv::Mat ConcreteFloorTexture(int size, double detail, std::uint64_t seed) {
  SeededRandom random(seed);
  cv::Mat image(size, size, CV_8UC3, cv::Scalar(138, 142, 146));
  Modulate(image, FractalNoise(size, size, size / 2.0, 7, random.Next()), 0.07 * detail);
  Modulate(image, FractalNoise(size, size, 3.0, 1, random.Next()), 0.03 * detail);  // grit
  Shade(image,
        BlobMask(size, size, random.Int(2, 2 + static_cast<int>(4 * detail)), size * 0.02,
                 size * 0.08, random),
        1.0 - 0.3 * std::min(detail, 1.5));  // oil stains
  for (int i = random.Int(1, 2 + static_cast<int>(3 * detail)); i > 0; --i)
    DrawCrack(image, random, detail);
  // Tyre marks: long faint arcs.
  cv::Mat tyres = cv::Mat::zeros(size, size, CV_32FC1);
  for (int i = random.Int(1, 3); i > 0; --i) {
    const cv::Point centre(random.Int(-size, 2 * size), random.Int(-size, 2 * size));
    const int radius = random.Int(size / 2, 2 * size);
    cv::ellipse(tyres, centre, {radius, radius}, 0, 0, 360, 1.0, random.Int(6, 14), cv::LINE_AA);
  }
  cv::GaussianBlur(tyres, tyres, cv::Size(9, 9), 0);
  Shade(image, tyres, 1.0 - 0.08 * detail);
  // Saw-cut joints along two edges (the next tile carries the opposite ones).
  cv::line(image, {0, 1}, {size, 1}, cv::Scalar(95, 98, 100), 2);
  cv::line(image, {1, 0}, {1, size}, cv::Scalar(95, 98, 100), 2);
  return image;
}

cv::Mat CeilingTexture(int size, std::uint64_t seed) {
  cv::Mat image(size, size, CV_8UC3, cv::Scalar(200, 202, 204));
  Modulate(image, FractalNoise(size, size, size / 4.0, 4, seed), 0.04);
  for (int i = 0; i <= 4; ++i) {
    const int at = i * (size - 1) / 4;
    cv::line(image, {at, 0}, {at, size}, cv::Scalar(150, 152, 154), 3);
    cv::line(image, {0, at}, {size, at}, cv::Scalar(150, 152, 154), 3);
  }
  return image;
}

cv::Mat CardboardTexture(int size, double detail, std::uint64_t seed) {
  SeededRandom random(seed);
  const double tint = random.Uniform(0.85, 1.1);
  cv::Mat image(size, size, CV_8UC3, Scale(cv::Scalar(92, 140, 182), tint));
  Modulate(image, FractalNoise(size, size, size / 3.0, 5, random.Next()), 0.06);
  // Tape across the top flaps, a printed label with a barcode, maybe an arrow symbol.
  const int tape = size / 7;
  cv::rectangle(image, cv::Rect(0, size / 2 - tape / 2, size, tape),
                Scale(cv::Scalar(120, 170, 205), tint), cv::FILLED);
  if (random.Chance(0.4 + 0.3 * detail)) {
    const cv::Rect label(random.Int(size / 10, size / 3), random.Int(size / 12, size / 5), size / 2,
                         size / 4);
    cv::rectangle(image, label, cv::Scalar(235, 238, 240), cv::FILLED);
    DrawTextBars(image, cv::Rect(label.x + 4, label.y + 4, label.width - 8, label.height / 2 - 4),
                 3, cv::Scalar(40, 40, 40), random);
    for (int x = label.x + 6; x < label.x + label.width - 6; x += random.Int(2, 5)) {
      cv::line(image, {x, label.y + label.height * 2 / 3}, {x, label.y + label.height - 4},
               cv::Scalar(20, 20, 20), random.Int(1, 2));
    }
  }
  if (random.Chance(0.5)) {
    const cv::Point base(size * 3 / 4, size * 7 / 8);
    cv::arrowedLine(image, base, base - cv::Point(0, size / 6), cv::Scalar(30, 40, 50), 3,
                    cv::LINE_AA, 0, 0.4);
  }
  return image;
}

cv::Mat WoodTexture(int width, int height, std::uint64_t seed) {
  SeededRandom random(seed);
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(110, 160, 196));
  cv::Mat grain = FractalNoise(width / 8 + 2, height, 4.0, 3, random.Next());
  cv::resize(grain, grain, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
  Modulate(image, grain, 0.12);
  const int boards = std::max(2, height / 40);
  for (int i = 1; i < boards; ++i) {
    const int y = i * height / boards;
    cv::line(image, {0, y}, {width, y}, cv::Scalar(50, 70, 90), 2);
  }
  return image;
}

cv::Mat MachinePanelTexture(int width, int height, const cv::Scalar& paint, std::uint64_t seed) {
  SeededRandom random(seed);
  cv::Mat image(height, width, CV_8UC3, paint);
  Modulate(image, FractalNoise(width, height, width / 4.0, 5, random.Next()), 0.05);
  const cv::Scalar groove = Scale(paint, 0.55);
  const int panels = random.Int(2, 3);
  for (int i = 1; i < panels; ++i) {
    const int x = i * width / panels;
    cv::line(image, {x, 0}, {x, height}, groove, 3);
  }
  for (int x = width / 20; x < width; x += width / 10) {  // rivets
    cv::circle(image, {x, height / 30}, 3, Scale(paint, 0.7), cv::FILLED, cv::LINE_AA);
    cv::circle(image, {x, height * 5 / 6}, 3, Scale(paint, 0.7), cv::FILLED, cv::LINE_AA);
  }
  // Vent grille on the first panel.
  const cv::Rect vent(width / 16, height / 8, width / panels - width / 8, height / 4);
  for (int y = vent.y; y < vent.y + vent.height; y += 10) {
    cv::rectangle(image, cv::Rect(vent.x, y, vent.width, 5), cv::Scalar(35, 35, 35), cv::FILLED);
  }
  // Control panel: dark box, display, coloured buttons.
  const cv::Rect panel(width - width / panels + width / 20, height / 6, width / panels - width / 10,
                       height / 3);
  cv::rectangle(image, panel, cv::Scalar(60, 62, 64), cv::FILLED);
  cv::rectangle(image, cv::Rect(panel.x + 8, panel.y + 8, panel.width / 2, panel.height / 3),
                cv::Scalar(90, 160, 60), cv::FILLED);
  const cv::Scalar buttons[] = {{40, 40, 220}, {40, 200, 40}, {30, 200, 230}, {200, 120, 40}};
  for (int i = 0; i < 4; ++i) {
    cv::circle(image,
               {panel.x + panel.width / 8 + i * panel.width / 4, panel.y + panel.height * 3 / 4},
               std::max(3, panel.width / 14), buttons[random.Int(0, 3)], cv::FILLED, cv::LINE_AA);
  }
  DrawTextBars(image, cv::Rect(width / 16, height / 2, width / 3, height / 10), 2,
               cv::Scalar(235, 235, 235), random);
  const cv::Mat stripes = HazardStripeTexture(width, height / 10);
  stripes.copyTo(image(cv::Rect(0, height - stripes.rows, width, stripes.rows)));
  return image;
}

cv::Mat HazardStripeTexture(int width, int height) {
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(20, 20, 20));
  const int period = std::max(8, height);
  for (int x = -height; x < width + height; x += period) {
    const cv::Point corners[] = {
        {x, height}, {x + period / 2, height}, {x + period / 2 + height, 0}, {x + height, 0}};
    cv::fillConvexPoly(image, corners, 4, cv::Scalar(0, 200, 245), cv::LINE_AA);
  }
  return image;
}

cv::Mat PosterTexture(int width, int height, std::uint64_t seed) {
  SeededRandom random(seed);
  const cv::Scalar palette[] = {{40, 40, 200},  {160, 90, 20},  {40, 150, 40},
                                {20, 160, 230}, {120, 40, 120}, {200, 200, 200}};
  const cv::Scalar background =
      random.Chance(0.5) ? cv::Scalar(240, 240, 240) : palette[random.Int(0, 4)];
  const cv::Scalar ink =
      background[0] > 200 ? palette[random.Int(0, 4)] : cv::Scalar(245, 245, 245);
  cv::Mat image(height, width, CV_8UC3, background);
  cv::rectangle(image, cv::Rect(0, 0, width, height / 6), ink, cv::FILLED);
  const std::vector<std::string> titles = {"SAFETY FIRST", "ZONE B", "NO FORKLIFTS",
                                           "HALL 2",       "EXIT",   "PPE REQUIRED",
                                           "DOCK AREA",    "QUALITY"};
  const std::string title = titles[random.Int(0, static_cast<int>(titles.size()) - 1)];
  const double scale = width / 260.0;
  cv::putText(image, title, {width / 20, height / 8}, cv::FONT_HERSHEY_DUPLEX, scale, background,
              std::max(1, static_cast<int>(2 * scale)), cv::LINE_AA);
  // A pictogram: a warning triangle, a circle sign or a large number.
  const cv::Point centre(width / 2, height * 9 / 20);
  const int r = width / 4;
  switch (random.Int(0, 2)) {
    case 0: {
      const cv::Point tri[] = {centre + cv::Point(0, -r), centre + cv::Point(r, r * 3 / 4),
                               centre + cv::Point(-r, r * 3 / 4)};
      cv::fillConvexPoly(image, tri, 3, cv::Scalar(0, 200, 245), cv::LINE_AA);
      cv::polylines(image, std::vector<std::vector<cv::Point>>{{tri[0], tri[1], tri[2]}}, true,
                    cv::Scalar(20, 20, 20), std::max(2, r / 8), cv::LINE_AA);
      cv::putText(image, "!", centre + cv::Point(-r / 8, r / 2), cv::FONT_HERSHEY_DUPLEX,
                  scale * 2.2, cv::Scalar(20, 20, 20), std::max(2, static_cast<int>(3 * scale)),
                  cv::LINE_AA);
      break;
    }
    case 1:
      cv::circle(image, centre, r, cv::Scalar(30, 30, 210), cv::FILLED, cv::LINE_AA);
      cv::rectangle(image, cv::Rect(centre.x - r * 3 / 4, centre.y - r / 6, r * 3 / 2, r / 3),
                    cv::Scalar(245, 245, 245), cv::FILLED);
      break;
    default:
      cv::putText(image, std::to_string(random.Int(1, 9)), centre + cv::Point(-r / 2, r / 2),
                  cv::FONT_HERSHEY_DUPLEX, scale * 4.0, ink,
                  std::max(3, static_cast<int>(6 * scale)), cv::LINE_AA);
  }
  DrawTextBars(image, cv::Rect(width / 10, height * 3 / 4, width * 8 / 10, height / 5), 4,
               background[0] > 200 ? cv::Scalar(60, 60, 60) : cv::Scalar(235, 235, 235), random);
  return image;
}

}  // namespace arucoslam
