#include "arucoslam/eval/svg_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace arucoslam {
namespace {

constexpr int kMarginLeft = 84;
constexpr int kMarginRight = 28;
constexpr int kMarginTop = 58;
constexpr int kMarginBottom = 64;
constexpr std::size_t kMaxPointsPerLine = 4000;
constexpr double kLegendSample = 30.0;     // px, length of a legend's line sample
constexpr double kLegendCharWidth = 7.4;   // px, approximate width of a 13 px character
constexpr double kLegendRowHeight = 22.0;  // px
constexpr const char* kFont = "DejaVu Sans, Helvetica, Arial, sans-serif";

std::string Escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

struct Range {
  double low = std::numeric_limits<double>::infinity();
  double high = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    if (!std::isfinite(v)) return;
    low = std::min(low, v);
    high = std::max(high, v);
  }
  bool Empty() const { return !(low <= high); }
  double Span() const { return high - low; }
  // Pads by a fraction of the span (or +-0.5 for a single value / nothing).
  void Pad(double fraction) {
    if (Empty()) {
      low = 0.0;
      high = 1.0;
      return;
    }
    const double pad = Span() > 0.0 ? fraction * Span() : std::max(0.5, std::abs(low) * 0.1);
    low -= pad;
    high += pad;
  }
  void Grow(double new_span) {
    const double centre = 0.5 * (low + high);
    low = centre - 0.5 * new_span;
    high = centre + 0.5 * new_span;
  }
};

// Maps data to pixels inside the plot area.
struct Frame {
  double left, top, width, height;
  Range x, y;
  double X(double v) const { return left + (v - x.low) / x.Span() * width; }
  double Y(double v) const { return top + height - (v - y.low) / y.Span() * height; }
};

std::string TickLabel(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::abs(value) < 0.5 * step) value = 0.0;  // no "-0"
  return fmt::format("{:.{}f}", value, decimals);
}

// Legend entries laid out in rows between the title and the plot area; unlabelled series
// are left out.
struct LegendEntry {
  const SvgPlot::Series* series;
  double x;  // px, left end of the sample line
  int row;
};

std::vector<LegendEntry> LayoutLegend(const std::vector<SvgPlot::Series>& series, double plot_left,
                                      double plot_width, int* rows) {
  std::vector<LegendEntry> entries;
  std::vector<double> row_widths = {0.0};
  for (const SvgPlot::Series& s : series) {
    if (s.label.empty()) continue;
    const double width = kLegendSample + 8.0 + kLegendCharWidth * s.label.size() + 22.0;
    if (row_widths.back() > 0.0 && row_widths.back() + width > plot_width) row_widths.push_back(0);
    entries.push_back({&s, row_widths.back(), static_cast<int>(row_widths.size()) - 1});
    row_widths.back() += width;
  }
  // Centre each row over the plot area.
  for (LegendEntry& entry : entries) {
    entry.x += plot_left + 0.5 * (plot_width - row_widths[entry.row] + 22.0);
  }
  *rows = entries.empty() ? 0 : static_cast<int>(row_widths.size());
  return entries;
}

Frame ComputeFrame(const SvgPlot::Options& options, const std::vector<SvgPlot::Series>& series) {
  const double plot_width = options.width - kMarginLeft - kMarginRight;
  int legend_rows = 0;
  LayoutLegend(series, kMarginLeft, plot_width, &legend_rows);
  const double top = kMarginTop + kLegendRowHeight * legend_rows;
  Frame frame{kMarginLeft, top, plot_width, options.height - top - kMarginBottom, {}, {}};
  for (const SvgPlot::Series& s : series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      frame.x.Add(s.x[i]);
      frame.y.Add(s.y[i]);
    }
  }
  if (options.y_from_zero) frame.y.Add(0.0);
  frame.x.Pad(options.equal_aspect ? 0.04 : 0.0);
  frame.y.Pad(0.05);
  if (options.y_from_zero && frame.y.low < 0.0 && frame.y.high > 0.0) frame.y.low = 0.0;
  if (options.equal_aspect) {
    const double per_pixel = std::max(frame.x.Span() / frame.width, frame.y.Span() / frame.height);
    frame.x.Grow(per_pixel * frame.width);
    frame.y.Grow(per_pixel * frame.height);
  }
  return frame;
}

// Grid, ticks, tick labels, the frame and the axis labels.
std::string RenderAxes(const SvgPlot::Options& options, const Frame& frame) {
  std::string out;
  const auto x_ticks = NiceTicks(frame.x.low, frame.x.high, std::max(3, options.width / 110));
  const auto y_ticks = NiceTicks(frame.y.low, frame.y.high, std::max(3, options.height / 80));
  const double x_step = x_ticks.size() > 1 ? x_ticks[1] - x_ticks[0] : 1.0;
  const double y_step = y_ticks.size() > 1 ? y_ticks[1] - y_ticks[0] : 1.0;
  const double bottom = frame.top + frame.height;
  for (double v : x_ticks) {
    const double px = frame.X(v);
    out += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#e3e3e3\"/>"
        "<line x1=\"{0:.1f}\" y1=\"{2:.1f}\" x2=\"{0:.1f}\" y2=\"{3:.1f}\" stroke=\"#444\"/>"
        "<text x=\"{0:.1f}\" y=\"{4:.1f}\" text-anchor=\"middle\" font-size=\"13\" "
        "fill=\"#333\">{5}</text>\n",
        px, frame.top, bottom, bottom + 5, bottom + 21, TickLabel(v, x_step));
  }
  for (double v : y_ticks) {
    const double py = frame.Y(v);
    out += fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{2:.1f}\" y2=\"{1:.1f}\" stroke=\"#e3e3e3\"/>"
        "<line x1=\"{3:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{1:.1f}\" stroke=\"#444\"/>"
        "<text x=\"{4:.1f}\" y=\"{5:.1f}\" text-anchor=\"end\" font-size=\"13\" "
        "fill=\"#333\">{6}</text>\n",
        frame.left, py, frame.left + frame.width, frame.left - 5, frame.left - 8, py + 4.5,
        TickLabel(v, y_step));
  }
  out += fmt::format(
      "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"none\" "
      "stroke=\"#444\"/>\n",
      frame.left, frame.top, frame.width, frame.height);
  out += fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"15\" "
      "fill=\"#222\">{}</text>\n",
      frame.left + frame.width / 2, bottom + 46.0, Escape(options.x_label));
  out += fmt::format(
      "<text transform=\"translate(22,{:.1f}) rotate(-90)\" text-anchor=\"middle\" "
      "font-size=\"15\" fill=\"#222\">{}</text>\n",
      frame.top + frame.height / 2, Escape(options.y_label));
  return out;
}

// A polyline (split at NaNs, thinned to kMaxPointsPerLine) or a set of markers.
std::string RenderSeries(const SvgPlot::Series& s, const Frame& frame) {
  std::string out;
  if (s.markers) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      out += fmt::format(
          "<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"{:.1f}\" fill=\"{}\" stroke=\"white\" "
          "stroke-width=\"1\"/>\n",
          frame.X(s.x[i]), frame.Y(s.y[i]), s.stroke_width, s.color);
    }
    return out;
  }
  const std::size_t stride = std::max<std::size_t>(1, s.x.size() / kMaxPointsPerLine);
  std::string points;
  const auto flush = [&] {
    if (points.empty()) return;
    out += fmt::format(
        "<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"{:.1f}\" "
        "stroke-linejoin=\"round\" stroke-linecap=\"round\"{} points=\"{}\"/>\n",
        s.color, s.stroke_width, s.dashed ? " stroke-dasharray=\"7,4\"" : "", points);
    points.clear();
  };
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const bool keep = i % stride == 0 || i + 1 == s.x.size() || !std::isfinite(s.y[i]);
    if (!keep) continue;
    if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
      flush();
      continue;
    }
    points += fmt::format("{:.2f},{:.2f} ", frame.X(s.x[i]), frame.Y(s.y[i]));
  }
  flush();
  return out;
}

std::string RenderLegend(const std::vector<SvgPlot::Series>& series, const Frame& frame) {
  int rows = 0;
  std::string out;
  for (const LegendEntry& entry : LayoutLegend(series, frame.left, frame.width, &rows)) {
    const SvgPlot::Series& s = *entry.series;
    const double cy = kMarginTop - 8.0 + kLegendRowHeight * (entry.row + 0.5);
    if (s.markers) {
      out += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{:.1f}\" fill=\"{}\"/>",
                         entry.x + 0.5 * kLegendSample, cy, s.stroke_width, s.color);
    } else {
      out += fmt::format(
          "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" "
          "stroke-width=\"{:.1f}\"{}/>",
          entry.x, cy, entry.x + kLegendSample, cy, s.color, std::max(2.5, s.stroke_width),
          s.dashed ? " stroke-dasharray=\"7,4\"" : "");
    }
    out += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"13\" fill=\"#222\">{}</text>\n",
                       entry.x + kLegendSample + 8.0, cy + 4.5, Escape(s.label));
  }
  return out;
}

}  // namespace

std::vector<double> NiceTicks(double low, double high, int target) {
  std::vector<double> ticks;
  if (!(high > low) || target < 1) return ticks;
  const double raw = (high - low) / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * magnitude;
    if (step >= raw) break;
  }
  for (double v = std::ceil(low / step - 1e-9) * step; v <= high + 1e-9 * step; v += step) {
    ticks.push_back(v);
  }
  return ticks;
}

SvgPlot::SvgPlot(Options options) : options_(std::move(options)) {
  if (!options_.Check()) throw std::invalid_argument("SvgPlot::Options: plot too small");
}

std::string SvgPlot::PaletteColor(std::size_t index) {
  static const char* kPalette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                   "#E69F00", "#56B4E9", "#8C564B"};
  return kPalette[index % (sizeof(kPalette) / sizeof(kPalette[0]))];
}

void SvgPlot::AddLine(const std::vector<double>& x, const std::vector<double>& y,
                      const std::string& label, const std::string& color, double stroke_width,
                      bool dashed) {
  if (x.size() != y.size()) throw std::invalid_argument("SvgPlot::AddLine: sizes differ");
  Series series{
      x,      y,    label, color.empty() ? PaletteColor(next_color_++) : color, stroke_width,
      dashed, false};
  series_.push_back(std::move(series));
}

void SvgPlot::AddMarkers(const std::vector<double>& x, const std::vector<double>& y,
                         const std::string& label, const std::string& color, double radius) {
  if (x.size() != y.size()) throw std::invalid_argument("SvgPlot::AddMarkers: sizes differ");
  series_.push_back(Series{x, y, label, color, radius, false, true});
}

std::string SvgPlot::Render() const { return RenderSvgDocument({*this}); }

std::string SvgPlot::RenderGroup(int offset_y) const {
  const Frame frame = ComputeFrame(options_, series_);
  std::string out = fmt::format("<g transform=\"translate(0,{})\">\n", offset_y);
  out += fmt::format("<rect x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" fill=\"white\"/>\n",
                     options_.width, options_.height);
  out += fmt::format(
      "<text x=\"{:.1f}\" y=\"34\" text-anchor=\"middle\" font-size=\"19\" "
      "font-weight=\"bold\" fill=\"#222\">{}</text>\n",
      options_.width / 2.0, Escape(options_.title));
  out += RenderAxes(options_, frame);
  // Data, clipped to the plot area.
  const std::string clip_id = fmt::format("clip{}", offset_y);
  out += fmt::format(
      "<clipPath id=\"{}\"><rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" "
      "height=\"{:.1f}\"/></clipPath>\n<g clip-path=\"url(#{})\">\n",
      clip_id, frame.left, frame.top, frame.width, frame.height, clip_id);
  for (const Series& s : series_) out += RenderSeries(s, frame);
  out += "</g>\n";
  out += RenderLegend(series_, frame);
  out += "</g>\n";
  return out;
}

std::string RenderSvgDocument(const std::vector<SvgPlot>& plots) {
  int width = 0;
  int height = 0;
  for (const SvgPlot& plot : plots) {
    width = std::max(width, plot.width());
    height += plot.height();
  }
  std::string out = fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" "
      "viewBox=\"0 0 {0} {1}\" font-family=\"{2}\">\n"
      "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      width, height, kFont);
  int offset = 0;
  for (const SvgPlot& plot : plots) {
    out += plot.RenderGroup(offset);
    offset += plot.height();
  }
  out += "</svg>\n";
  return out;
}

}  // namespace arucoslam
