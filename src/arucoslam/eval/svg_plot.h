// SvgPlot: a small 2-D line/marker chart written as SVG (title, axes with units and ticks,
// grid, legend); several plots stack into one document with RenderSvgDocument.
#pragma once

#include <string>
#include <vector>

#include "arucoslam/util/option_check.h"

namespace arucoslam {

class SvgPlot {
 public:
  struct Options {
    std::string title;
    std::string x_label;  // with the unit, e.g. "x [m]"
    std::string y_label;
    int width = 960;            // px
    int height = 600;           // px
    bool equal_aspect = false;  // same metres per pixel on both axes (top-down views)
    bool y_from_zero = false;   // include 0 in the y range (error plots)

    bool Check(std::string* why = nullptr) const {
      OptionCheck check(why);
      check.AtLeast("width", width, 200);
      check.AtLeast("height", height, 150);
      return check.ok();
    }
  };

  explicit SvgPlot(Options options);

  // A polyline; a NaN in `y` breaks it (a tracking gap). `color` empty: next palette colour.
  void AddLine(const std::vector<double>& x, const std::vector<double>& y, const std::string& label,
               const std::string& color = "", double stroke_width = 1.8, bool dashed = false);
  // Round markers (start/end points, samples); an empty label keeps them out of the legend.
  void AddMarkers(const std::vector<double>& x, const std::vector<double>& y,
                  const std::string& label, const std::string& color, double radius = 4.0);

  int width() const { return options_.width; }
  int height() const { return options_.height; }
  // A standalone SVG document.
  std::string Render() const;
  // The chart as an SVG group translated down by `offset_y` pixels (for stacking).
  std::string RenderGroup(int offset_y) const;

  // Palette colour i (colour-blind safe, cycles).
  static std::string PaletteColor(std::size_t index);

  // One data series as stored (public for the renderer's helpers).
  struct Series {
    std::vector<double> x;
    std::vector<double> y;
    std::string label;
    std::string color;
    double stroke_width = 1.8;
    bool dashed = false;
    bool markers = false;
  };

 private:
  Options options_;
  std::vector<Series> series_;
  std::size_t next_color_ = 0;
};

// Plots stacked vertically in one SVG document.
std::string RenderSvgDocument(const std::vector<SvgPlot>& plots);

// Tick positions: multiples of 1, 2 or 5 x 10^k covering [low, high], about `target` ticks.
std::vector<double> NiceTicks(double low, double high, int target);

}  // namespace arucoslam
