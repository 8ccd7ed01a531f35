// SPDX-License-Identifier: BSD-2-Clause
#include "io/plot.hpp"

#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/atomic_file.hpp"

namespace pednav::io {
namespace {

// A gnuplot single-quoted string (no backslash processing; a quote is doubled).
std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'') q += '\'';
    q += c;
  }
  return q + "'";
}

std::string number(double v) { return fmt::format("{:.9g}", v); }

// Data block of one series: "x y" (or "x low high" for bands); a non-finite value breaks the line (blank line).
std::string data_block(const PlotSeries& s, size_t index) {
  std::string d = fmt::format("$d{} << EOD\n", index);
  bool gap = false;
  for (size_t i = 0; i < s.x.size(); ++i) {
    if (s.style == PlotStyle::kBand) {
      if (i >= s.y_low.size() || i >= s.y_high.size()) break;
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y_low[i]) || !std::isfinite(s.y_high[i])) {
        if (!gap) d += "\n";
        gap = true;
        continue;
      }
      d += number(s.x[i]) + " " + number(s.y_low[i]) + " " + number(s.y_high[i]) + "\n";
    } else {
      if (i >= s.y.size()) break;
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        if (!gap) d += "\n";
        gap = true;
        continue;
      }
      d += number(s.x[i]) + " " + number(s.y[i]) + "\n";
    }
    gap = false;
  }
  return d + "EOD\n";
}

}  // namespace

std::string gnuplot_script(const PlotSpec& spec, const std::string& svg_path) {
  std::string g;
  g += fmt::format("set terminal svg size {},{} noenhanced font 'sans,12' background '#ffffff'\n", spec.width_px, spec.height_px);
  g += "set output " + quoted(svg_path) + "\n";
  g += "set encoding utf8\nset grid lc rgb '#dddddd'\nset key top left box opaque\n";
  if (!spec.title.empty()) g += "set title " + quoted(spec.title) + "\n";
  if (!spec.x_label.empty()) g += "set xlabel " + quoted(spec.x_label) + "\n";
  if (!spec.y_label.empty()) g += "set ylabel " + quoted(spec.y_label) + "\n";
  if (spec.equal_axes) g += "set size ratio -1\n";
  if (std::isfinite(spec.y_min) && std::isfinite(spec.y_max)) {
    g += fmt::format("set yrange [{}:{}]\n", spec.y_min, spec.y_max);
  } else if (spec.y_from_zero) {
    g += "set yrange [0:*]\n";
  }
  for (size_t i = 0; i < spec.series.size(); ++i) g += data_block(spec.series[i], i);
  std::string plot;
  for (size_t i = 0; i < spec.series.size(); ++i) {
    const PlotSeries& s = spec.series[i];
    const bool empty = s.x.empty();
    std::string item = empty ? "NaN notitle" : fmt::format("$d{}", i);
    if (!empty) {
      const std::string color = s.color.empty() ? "" : " lc rgb " + quoted(s.color);
      switch (s.style) {
        case PlotStyle::kLines: item += " using 1:2 with lines lw " + number(s.width) + color; break;
        case PlotStyle::kPoints: item += " using 1:2 with points pt 7 ps " + number(s.width * 0.3) + color; break;
        case PlotStyle::kSteps: item += " using 1:2 with steps lw " + number(s.width) + color; break;
        case PlotStyle::kBand: item += " using 1:2:3 with filledcurves fs transparent solid 0.25 noborder" + color; break;
      }
      item += s.title.empty() ? " notitle" : " title " + quoted(s.title);
    }
    plot += (i == 0 ? "plot " : ", \\\n     ") + item;
  }
  if (plot.empty()) plot = "plot NaN notitle";
  g += plot + "\nunset output\n";
  return g;
}

Expected<std::string> render_svg(const PlotSpec& spec) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::string tmpl = (fs::temp_directory_path(ec) / "pednav-plot-XXXXXX").string();
  if (ec || mkdtemp(tmpl.data()) == nullptr) return make_error("plot: cannot create a temporary folder");
  const fs::path dir(tmpl);
  const fs::path script = dir / "plot.gp", svg = dir / "plot.svg", err = dir / "gnuplot.err";
  {
    std::ofstream f(script);
    f << gnuplot_script(spec, svg.string());
  }
  const char* env = std::getenv("PEDNAV_GNUPLOT");
  const std::string exe = env && *env ? env : "gnuplot";
  const std::string cmd = exe + " " + quoted(script.string()) + " 2> " + quoted(err.string());
  const int rc = std::system(cmd.c_str());
  std::string svg_text, err_text;
  {
    std::ifstream f(svg);
    std::stringstream ss;
    ss << f.rdbuf();
    svg_text = ss.str();
    std::ifstream fe(err);
    std::stringstream se;
    se << fe.rdbuf();
    err_text = se.str();
  }
  fs::remove_all(dir, ec);
  if (rc != 0 || svg_text.find("<svg") == std::string::npos) {
    if (!err_text.empty() && err_text.back() == '\n') err_text.pop_back();
    if (rc != 0 && (err_text.find("not found") != std::string::npos || WEXITSTATUS(rc) == 127)) {
      return make_error("plot '" + spec.title + "': " + exe +
                        " not found (install the Debian package gnuplot-nox; scripts/setup does)");
    }
    return make_error("plot '" + spec.title + "': gnuplot failed (exit " + std::to_string(rc) + "): " + err_text);
  }
  return svg_text;
}

Expected<void> write_plot_svg(const std::string& path, const PlotSpec& spec) {
  auto svg = render_svg(spec);
  if (!svg) return svg.error();
  return write_file_atomic(path, *svg);
}

}  // namespace pednav::io
