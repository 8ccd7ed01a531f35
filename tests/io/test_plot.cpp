// SPDX-License-Identifier: BSD-2-Clause
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
  EXPECT_THAT(g, Not(HasSubstr("set yrange")));
  PlotSpec fixed = two_series();
  fixed.y_from_zero = true;
  EXPECT_THAT(gnuplot_script(fixed, "/tmp/x.svg"), HasSubstr("set yrange [0:*]\n"));
  fixed.y_min = -0.5;
  fixed.y_max = 3.5;  // a fixed range wins over y_from_zero
  const std::string gf = gnuplot_script(fixed, "/tmp/x.svg");
  EXPECT_THAT(gf, HasSubstr("set yrange [-0.5:3.5]\n"));
  EXPECT_THAT(gf, Not(HasSubstr("set yrange [0:*]")));
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

TEST(PlotFigures, MontecarloNeesSigmaAndDistance) {
  std::vector<eval::McEpochStats> fwd(3), smo(3);
  for (int i = 0; i < 3; ++i) {
    eval::McEpochStats& e = fwd[static_cast<size_t>(i)];
    e.t_s = 10.0 * i;
    e.distance_m = 100.0 * i;
    e.nees_horizontal = 2.0 + 0.1 * i;
    e.nees_lo_2dof = 1.6;
    e.nees_hi_2dof = 2.4 + 0.01 * i;
    e.sample_sd_ned_m = Eigen::Vector3d(0.5 + i, 0.4, 0.0);
    e.filter_sd_ned_m = Eigen::Vector3d(0.6, 0.3 + i, 0.0);
    e.sample_sd_yaw_rad = 0.01;
    e.filter_sd_yaw_rad = 0.02;
    e.rms_horizontal_m = 1.0 + i;
    smo[static_cast<size_t>(i)] = e;
    smo[static_cast<size_t>(i)].nees_horizontal = 3.0;
  }
  const PlotSpec n = montecarlo_nees_plot("t", fwd, smo);
  ASSERT_EQ(n.series.size(), 3u);  // band, forward, smoothed
  EXPECT_EQ(n.series[0].style, PlotStyle::kBand);
  EXPECT_DOUBLE_EQ(n.series[0].y_low[2], 1.6);
  EXPECT_DOUBLE_EQ(n.series[0].y_high[2], 2.42);
  EXPECT_DOUBLE_EQ(n.series[1].y[1], 2.1);
  EXPECT_DOUBLE_EQ(n.series[2].y[0], 3.0);
  EXPECT_EQ(montecarlo_nees_plot("t", fwd, {}).series.size(), 2u);  // no smoothed solution: no smoothed line

  const PlotSpec s = montecarlo_sigma_plot("t", fwd, false);
  ASSERT_EQ(s.series.size(), 4u);  // north filter, north sample, east filter, east sample
  EXPECT_DOUBLE_EQ(s.series[0].y[2], 0.6);
  EXPECT_DOUBLE_EQ(s.series[1].y[2], 2.5);
  EXPECT_DOUBLE_EQ(s.series[2].y[2], 2.3);
  EXPECT_DOUBLE_EQ(s.series[3].y[2], 0.4);
  const PlotSpec y = montecarlo_sigma_plot("t", fwd, true);
  ASSERT_EQ(y.series.size(), 2u);
  EXPECT_NEAR(y.series[0].y[0], 0.02 * 180.0 / M_PI, 1e-12);  // degrees

  const PlotSpec d = montecarlo_distance_plot("t", fwd, smo);
  ASSERT_EQ(d.series.size(), 3u);  // the 3 % line, forward, smoothed
  EXPECT_DOUBLE_EQ(d.series[0].x.back(), 200.0);
  EXPECT_DOUBLE_EQ(d.series[0].y.back(), 6.0);
  EXPECT_DOUBLE_EQ(d.series[1].x[1], 100.0);
  EXPECT_DOUBLE_EQ(d.series[1].y[1], 2.0);
}

}  // namespace
}  // namespace pednav::io
