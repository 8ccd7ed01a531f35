// io/plot.* (gnuplot as SVG renderer) and io/plot_figures.*: the script carries the data and styles, gnuplot
// renders it, a missing gnuplot is a clear message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <stdlib.h>

#include <cmath>

#include "io/plot.hpp"
#include "io/plot_figures.hpp"

namespace pednav::io {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

PlotSpec two_series() {
  PlotSpec p;
  p.title = "Test 'plot' sd_n_m";
  p.x_label = "t [s]";
  p.y_label = "e [m]";
  p.series.push_back({"line", PlotStyle::kLines, {0, 1, 2, 3}, {0.5, NAN, 2.5, 3.5}, {}, {}, "#123456", 1.5});
  p.series.push_back({"band", PlotStyle::kBand, {0, 1}, {}, {-1, -2}, {1, 2}, "", 1.0});
  return p;
}

TEST(Plot, ScriptHasDataBlocksStylesAndBreaksAtNaN) {
  const std::string g = gnuplot_script(two_series(), "/tmp/x.svg");
  EXPECT_THAT(g, HasSubstr("set terminal svg"));
  EXPECT_THAT(g, HasSubstr("set output '/tmp/x.svg'"));
  EXPECT_THAT(g, HasSubstr("set title 'Test ''plot'' sd_n_m'"));
  EXPECT_THAT(g, HasSubstr("$d0 << EOD\n0 0.5\n\n2 2.5\n3 3.5\nEOD\n"));  // NaN -> blank line (line break)
  EXPECT_THAT(g, HasSubstr("$d1 << EOD\n0 -1 1\n1 -2 2\nEOD\n"));
  EXPECT_THAT(g, HasSubstr("with lines lw 1.5 lc rgb '#123456' title 'line'"));
  EXPECT_THAT(g, HasSubstr("using 1:2:3 with filledcurves"));
  EXPECT_THAT(g, Not(HasSubstr("nan")));
}

TEST(Plot, GnuplotRendersSvg) {
  auto svg = render_svg(two_series());
  ASSERT_TRUE(svg.has_value()) << svg.error().message << " (scripts/setup installs gnuplot-nox)";
  EXPECT_THAT(*svg, HasSubstr("<svg"));
  EXPECT_THAT(*svg, HasSubstr("</svg>"));
  EXPECT_THAT(*svg, HasSubstr("Test 'plot' sd_n_m"));  // the title reached the picture verbatim (noenhanced)
}

TEST(Plot, MissingGnuplotSaysHowToInstall) {
  const char* old = getenv("PEDNAV_GNUPLOT");
  const std::string saved = old ? old : "";
  setenv("PEDNAV_GNUPLOT", "/nonexistent/gnuplot", 1);
  auto svg = render_svg(two_series());
  if (old) {
    setenv("PEDNAV_GNUPLOT", saved.c_str(), 1);
  } else {
    unsetenv("PEDNAV_GNUPLOT");
  }
  ASSERT_FALSE(svg.has_value());
  EXPECT_THAT(svg.error().message, HasSubstr("not found (install the Debian package gnuplot-nox"));
}

TEST(PlotFigures, ZuptFractionAndEnvelope) {
  const std::vector<double> t{0, 1, 2, 3, 4, 5}, z{1, 0, 1, 0, 1, 0};
  const PlotSpec p = zupt_plot(t, z, 2.0);  // centred window of 2 s: 3 samples inside, 2 at the ends
  ASSERT_EQ(p.series.size(), 2u);
  EXPECT_NEAR(p.series[1].y[0], 0.5, 1e-12);        // {1, 0}
  EXPECT_NEAR(p.series[1].y[1], 2.0 / 3.0, 1e-12);  // {1, 0, 1}
  EXPECT_NEAR(p.series[1].y[2], 1.0 / 3.0, 1e-12);  // {0, 1, 0}
  const PlotSpec e = error_envelope_plot("t", "North", {0, 1}, {0.1, -0.2}, {0.5, NAN});
  ASSERT_EQ(e.series[0].style, PlotStyle::kBand);
  EXPECT_NEAR(e.series[0].y_high[0], 1.5, 1e-12);
  EXPECT_NEAR(e.series[0].y_low[0], -1.5, 1e-12);
  EXPECT_TRUE(std::isnan(e.series[0].y_high[1]));
}

}  // namespace
}  // namespace pednav::io
