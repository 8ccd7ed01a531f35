// SPDX-License-Identifier: BSD-2-Clause
#include "io/plot_figures.hpp"

#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"
#include "eval/outage.hpp"

namespace pednav::io {

EnTrack to_en_track(const std::string& name, const std::vector<Eigen::Vector3d>& p_e, const Eigen::Vector3d& p0_e,
                    const std::string& color) {
  EnTrack t;
  t.name = name;
  t.color = color;
  const Geodetic llh = geodetic_from_ecef(p0_e);
  const Eigen::Matrix3d R_n_e = R_e_n(llh.lat, llh.lon).transpose();
  for (const auto& p : p_e) {
    const Eigen::Vector3d d_n = R_n_e * (p - p0_e);  // NED
    t.e_m.push_back(d_n.y());
    t.n_m.push_back(d_n.x());
  }
  return t;
}

PlotSpec trajectory_plot(const std::string& title, const std::vector<EnTrack>& tracks) {
  PlotSpec p;
  p.title = title;
  p.x_label = "East [m]";
  p.y_label = "North [m]";
  p.equal_axes = true;
  p.height_px = 620;
  for (const auto& t : tracks) {
    PlotSeries s;
    s.title = t.name;
    s.x = t.e_m;
    s.y = t.n_m;
    s.color = t.color;
    s.style = t.style;
    s.width = t.style == PlotStyle::kPoints ? 2.0 : 1.5;
    p.series.push_back(std::move(s));
  }
  return p;
}

PlotSpec error_envelope_plot(const std::string& title, const std::string& component, const std::vector<double>& t_s,
                             const std::vector<double>& error_m, const std::vector<double>& sigma_m) {
  PlotSpec p;
  p.title = title;
  p.x_label = "time since start [s]";
  p.y_label = component + " error [m]";
  PlotSeries band;
  band.title = "±3σ (filter)";
  band.style = PlotStyle::kBand;
  band.color = "#1f77b4";
  for (size_t i = 0; i < t_s.size() && i < sigma_m.size(); ++i) {
    band.x.push_back(t_s[i]);
    band.y_low.push_back(-3.0 * sigma_m[i]);
    band.y_high.push_back(3.0 * sigma_m[i]);
  }
  p.series.push_back(std::move(band));
  p.series.push_back({component + " error", PlotStyle::kLines, t_s, error_m, {}, {}, "#d62728", 1.2});
  return p;
}

PlotSpec horizontal_error_plot(const std::string& title, const std::vector<ErrorSeries>& series) {
  PlotSpec p;
  p.title = title;
  p.x_label = "time since start [s]";
  p.y_label = "horizontal error [m]";
  p.y_from_zero = true;
  for (const auto& s : series) p.series.push_back({s.name, PlotStyle::kLines, s.t_s, s.value_m, {}, {}, s.color, 1.2});
  return p;
}

PlotSpec error_cdf_plot(const std::string& title, const std::vector<ErrorSeries>& series) {
  PlotSpec p;
  p.title = title;
  p.x_label = "horizontal error [m]";
  p.y_label = "fraction of epochs <= error";
  p.y_from_zero = true;
  for (const auto& s : series) {
    const eval::Cdf c = eval::empirical_cdf(s.value_m);
    p.series.push_back({s.name, PlotStyle::kSteps, c.value, c.fraction, {}, {}, s.color, 1.8});
  }
  return p;
}

PlotSpec satellites_plot(const std::vector<double>& t_s, const std::vector<double>& used,
                         const std::vector<double>& rejected) {
  PlotSpec p;
  p.title = "Satellites per epoch";
  p.x_label = "time since start [s]";
  p.y_label = "satellites";
  p.y_from_zero = true;
  p.height_px = 360;
  p.series.push_back({"used", PlotStyle::kSteps, t_s, used, {}, {}, "#2ca02c", 1.2});
  p.series.push_back({"rejected (fault detection)", PlotStyle::kSteps, t_s, rejected, {}, {}, "#d62728", 1.2});
  return p;
}

PlotSpec zupt_plot(const std::vector<double>& t_s, const std::vector<double>& zupt, double window_s) {
  PlotSpec p;
  p.title = "ZUPT timeline";
  p.x_label = "time since start [s]";
  p.y_label = "ZUPT (1 = stance at the output epoch)";
  p.y_from_zero = true;
  p.height_px = 320;
  p.series.push_back({"ZUPT flag at output epochs", PlotStyle::kPoints, t_s, zupt, {}, {}, "#7f7f7f", 1.5});
  // Moving fraction over window_s (centred).
  std::vector<double> frac(t_s.size(), NAN);
  size_t lo = 0, hi = 0;
  double sum = 0.0;
  int n = 0;
  for (size_t i = 0; i < t_s.size(); ++i) {
    while (hi < t_s.size() && t_s[hi] <= t_s[i] + 0.5 * window_s) {
      if (std::isfinite(zupt[hi])) {
        sum += zupt[hi];
        ++n;
      }
      ++hi;
    }
    while (lo < hi && t_s[lo] < t_s[i] - 0.5 * window_s) {
      if (std::isfinite(zupt[lo])) {
        sum -= zupt[lo];
        --n;
      }
      ++lo;
    }
    if (n > 0) frac[i] = sum / n;
  }
  p.series.push_back({"fraction of epochs in stance (moving " + std::to_string(static_cast<int>(window_s)) + " s)",
                      PlotStyle::kLines, t_s, frac, {}, {}, "#9467bd", 2.0});
  return p;
}

PlotSpec outage_rms_plot(const std::string& title, const std::vector<double>& t_since_s,
                         const std::vector<double>& rms_forward_m, const std::vector<double>& rms_smoothed_m) {
  PlotSpec p;
  p.title = title;
  p.x_label = "time since outage start [s]";
  p.y_label = "RMS horizontal error across windows [m]";
  p.y_from_zero = true;
  p.series.push_back({"forward", PlotStyle::kLines, t_since_s, rms_forward_m, {}, {}, "#1f77b4", 2.2});
  if (!rms_smoothed_m.empty()) {
    p.series.push_back({"smoothed", PlotStyle::kLines, t_since_s, rms_smoothed_m, {}, {}, "#d62728", 2.2});
  }
  return p;
}

namespace {

// An empty plot with its y axis from zero.
PlotSpec zero_based_plot(const std::string& title, const char* x_label, const char* y_label) {
  PlotSpec p;
  p.title = title;
  p.x_label = x_label;
  p.y_label = y_label;
  p.y_from_zero = true;
  return p;
}

// One line of a Monte Carlo figure: x(e), y(e) over the epochs.
using EpochValue = double (*)(const eval::McEpochStats&);
PlotSeries epoch_line(const std::string& name, const std::vector<eval::McEpochStats>& epochs, EpochValue x,
                      EpochValue y, const char* color, double width) {
  PlotSeries s{name, PlotStyle::kLines, {}, {}, {}, {}, color, width};
  for (const auto& e : epochs) {
    s.x.push_back(x(e));
    s.y.push_back(y(e));
  }
  return s;
}
double time_s(const eval::McEpochStats& e) { return e.t_s; }

}  // namespace

PlotSpec montecarlo_nees_plot(const std::string& title, const std::vector<eval::McEpochStats>& forward,
                              const std::vector<eval::McEpochStats>& smoothed) {
  PlotSpec p = zero_based_plot(title, "time since the scenario start [s]", "average horizontal NEES (2 dof)");
  PlotSeries band{"95 % band of the average", PlotStyle::kBand, {}, {}, {}, {}, "#dddddd", 1.0};
  for (const auto& e : forward) {
    band.x.push_back(e.t_s);
    band.y_low.push_back(e.nees_lo_2dof);
    band.y_high.push_back(e.nees_hi_2dof);
  }
  const EpochValue nees = [](const eval::McEpochStats& e) { return e.nees_horizontal; };
  p.series.push_back(std::move(band));
  p.series.push_back(epoch_line("forward", forward, time_s, nees, "#1f77b4", 1.5));
  if (!smoothed.empty()) p.series.push_back(epoch_line("smoothed", smoothed, time_s, nees, "#d62728", 1.5));
  return p;
}

PlotSpec montecarlo_sigma_plot(const std::string& title, const std::vector<eval::McEpochStats>& epochs, bool yaw) {
  PlotSpec p = zero_based_plot(title, "time since the scenario start [s]",
                               yaw ? "yaw error sigma [deg]" : "position error sigma [m]");
  struct Axis {
    const char* name;
    const char *sample_color, *filter_color;
    EpochValue sample, filter;
  };
  const std::vector<Axis> axes =
      yaw ? std::vector<Axis>{{"yaw", "#2ca02c", "#98df8a",
                               [](const eval::McEpochStats& e) { return e.sample_sd_yaw_rad * kRadToDeg; },
                               [](const eval::McEpochStats& e) { return e.filter_sd_yaw_rad * kRadToDeg; }}}
          : std::vector<Axis>{{"north", "#1f77b4", "#9ecae1",
                               [](const eval::McEpochStats& e) { return e.sample_sd_ned_m.x(); },
                               [](const eval::McEpochStats& e) { return e.filter_sd_ned_m.x(); }},
                              {"east", "#d62728", "#fc9272",
                               [](const eval::McEpochStats& e) { return e.sample_sd_ned_m.y(); },
                               [](const eval::McEpochStats& e) { return e.filter_sd_ned_m.y(); }}};
  for (const Axis& a : axes) {
    p.series.push_back(epoch_line(std::string(a.name) + ": filter sigma", epochs, time_s, a.filter, a.filter_color, 2.5));
    p.series.push_back(
        epoch_line(std::string(a.name) + ": sample sigma of the error", epochs, time_s, a.sample, a.sample_color, 1.5));
  }
  return p;
}

PlotSpec montecarlo_distance_plot(const std::string& title, const std::vector<eval::McEpochStats>& forward,
                                  const std::vector<eval::McEpochStats>& smoothed) {
  PlotSpec p = zero_based_plot(title, "distance walked [m]", "RMS horizontal error across the runs [m]");
  double d_max = 0.0;
  for (const auto& e : forward) d_max = std::max(d_max, e.distance_m);
  p.series.push_back({"3 % of the distance", PlotStyle::kLines, {0.0, d_max}, {0.0, 0.03 * d_max}, {}, {}, "#7f7f7f", 1.0});
  const EpochValue d = [](const eval::McEpochStats& e) { return e.distance_m; };
  const EpochValue rms = [](const eval::McEpochStats& e) { return e.rms_horizontal_m; };
  p.series.push_back(epoch_line("forward", forward, d, rms, "#1f77b4", 1.5));
  if (!smoothed.empty()) p.series.push_back(epoch_line("smoothed", smoothed, d, rms, "#d62728", 1.5));
  return p;
}

}  // namespace pednav::io
