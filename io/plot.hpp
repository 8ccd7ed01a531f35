// SPDX-License-Identifier: BSD-2-Clause
// Plots as SVG through gnuplot (Debian package gnuplot-nox, run as a subprocess; scripts/setup installs it).
// A plot is described as data (PlotSpec); gnuplot_script() turns it into a gnuplot script with inline data blocks
// and render_svg() runs gnuplot on it. Nothing here draws by hand.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/expected.hpp"

namespace pednav::io {

enum class PlotStyle {
  kLines,   ///< polyline (non-finite y breaks the line)
  kPoints,  ///< markers
  kSteps,   ///< step function (counts per epoch)
  kBand,    ///< filled band between y_low and y_high (e.g. a +-3 sigma envelope)
};

/// One data series of a plot.
struct PlotSeries {
  std::string title;               ///< legend entry (empty: none)
  PlotStyle style = PlotStyle::kLines;
  std::vector<double> x, y;        ///< same length (kBand: y unused)
  std::vector<double> y_low, y_high;  ///< kBand only, same length as x
  std::string color;               ///< gnuplot colour name or "#rrggbb"; empty: gnuplot's sequence
  double width = 1.5;              ///< line width / point size
};

struct PlotSpec {
  std::string title, x_label, y_label;
  std::vector<PlotSeries> series;
  bool equal_axes = false;         ///< same scale on x and y (maps in metres)
  bool y_from_zero = false;        ///< y axis starts at 0
  double y_min = NAN, y_max = NAN;  ///< fixed y range when both are finite (overrides y_from_zero)
  int width_px = 820, height_px = 460;
};

/// The gnuplot script that writes `spec` as SVG to `svg_path` (data inline as data blocks).
std::string gnuplot_script(const PlotSpec& spec, const std::string& svg_path);

/// Run gnuplot (env PEDNAV_GNUPLOT or `gnuplot` on PATH) and return the SVG text. Fails with gnuplot's own
/// message, or with how to install it when it is missing.
Expected<std::string> render_svg(const PlotSpec& spec);

/// render_svg() and write the result atomically to `path`.
Expected<void> write_plot_svg(const std::string& path, const PlotSpec& spec);

}  // namespace pednav::io
