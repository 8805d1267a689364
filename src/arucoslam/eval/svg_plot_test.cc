#include "arucoslam/eval/svg_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace arucoslam {
namespace {

int Count(const std::string& text, const std::string& what) {
  int count = 0;
  for (std::size_t pos = text.find(what); pos != std::string::npos;
       pos = text.find(what, pos + 1)) {
    ++count;
  }
  return count;
}

TEST(SvgPlot, NiceTicksAreRoundNumbersCoveringTheRange) {
  EXPECT_EQ(NiceTicks(0.0, 10.0, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  const std::vector<double> ticks = NiceTicks(-0.013, 0.087, 5);
  ASSERT_EQ(ticks.size(), 5u);  // step 0.02 from -0.0 to 0.08
  EXPECT_NEAR(ticks.front(), 0.0, 1e-15);
  EXPECT_NEAR(ticks[1] - ticks[0], 0.02, 1e-15);
  EXPECT_TRUE(NiceTicks(1.0, 1.0, 5).empty());
}

TEST(SvgPlot, RendersTitleAxesLegendAndBreaksLinesAtNaN) {
  SvgPlot plot({"Error <over> time", "time [s]", "error [m]", 800, 500, false, true});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  plot.AddLine({0, 1, 2, 3, 4}, {0.1, 0.2, nan, 0.3, 0.1}, "run A");
  plot.AddMarkers({2.0}, {0.25}, "", "#000000");
  const std::string svg = plot.Render();
  EXPECT_NE(svg.find("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"800\" height=\"500\""),
            std::string::npos);
  EXPECT_NE(svg.find("Error &lt;over&gt; time"), std::string::npos);  // escaped
  EXPECT_NE(svg.find(">time [s]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">error [m]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">run A</text>"), std::string::npos);
  EXPECT_EQ(Count(svg, "<polyline"), 2);  // split at the NaN
  EXPECT_EQ(Count(svg, "<circle"), 1);    // unlabelled markers: not in the legend
  EXPECT_EQ(Count(svg, "<g"), Count(svg, "</g>"));
  EXPECT_EQ(svg.find("nan"), std::string::npos);
}

TEST(SvgPlot, EqualAspectKeepsMetresPerPixelEqual) {
  SvgPlot plot({"top", "x [m]", "y [m]", 600, 400, true, false});
  plot.AddLine({0.0, 10.0}, {0.0, 1.0}, "");
  // A 10 m x 1 m path in a 496 x 278 px area (after margins): x decides the scale.
  const std::string svg = plot.Render();
  const std::size_t at = svg.find("points=\"");
  ASSERT_NE(at, std::string::npos);
  double x0, y0, x1, y1;
  ASSERT_EQ(std::sscanf(svg.c_str() + at, "points=\"%lf,%lf %lf,%lf", &x0, &y0, &x1, &y1), 4);
  const double pixels_per_metre_x = (x1 - x0) / 10.0;
  const double pixels_per_metre_y = (y0 - y1) / 1.0;
  EXPECT_NEAR(pixels_per_metre_x, pixels_per_metre_y, 0.02);
}

TEST(SvgPlot, StackedDocumentHoldsEveryPanel) {
  std::vector<SvgPlot> panels;
  for (int i = 0; i < 3; ++i) {
    panels.emplace_back(SvgPlot::Options{"panel", "t [s]", "v", 700, 300, false, false});
    panels.back().AddLine({0, 1}, {i, i + 1.0}, "s");
  }
  const std::string svg = RenderSvgDocument(panels);
  EXPECT_NE(svg.find("height=\"900\""), std::string::npos);
  EXPECT_EQ(Count(svg, "<polyline"), 3);
  EXPECT_EQ(Count(svg, "clipPath id="), 3);
  EXPECT_NE(svg.find("translate(0,600)"), std::string::npos);
}

}  // namespace
}  // namespace arucoslam
