// SPDX-License-Identifier: BSD-2-Clause
// The standard figures of pednav (compare, report, outage) as PlotSpecs for io/plot.hpp: trajectory against the
// reference in local East/North, error vs time with the +-3 sigma envelope, error CDF, satellites used/rejected,
// ZUPT timeline, outage RMS vs time since the outage started, Monte Carlo consistency (seed 000 Figs. 4-6).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "eval/montecarlo.hpp"
#include "eval/trajectory.hpp"
#include "io/plot.hpp"

namespace pednav::io {

/// One trajectory in local East/North [m] for the map plot.
struct EnTrack {
  std::string name;
  std::vector<double> e_m, n_m;
  std::string color;
  PlotStyle style = PlotStyle::kLines;
};

/// Positions (ECEF [m]) to East/North [m] about the origin p0_e (ECEF [m]).
EnTrack to_en_track(const std::string& name, const std::vector<Eigen::Vector3d>& p_e, const Eigen::Vector3d& p0_e,
                    const std::string& color);

/// Map: tracks in East/North with equal axes.
PlotSpec trajectory_plot(const std::string& title, const std::vector<EnTrack>& tracks);

/// One error component vs time with its +-3 sigma envelope. t_s: seconds since the run's start; error_m and
/// sigma_m: same length (sigma NaN where unknown: no envelope there).
PlotSpec error_envelope_plot(const std::string& title, const std::string& component, const std::vector<double>& t_s,
                             const std::vector<double>& error_m, const std::vector<double>& sigma_m);

/// Horizontal error vs time of several solutions (name, t_s, horizontal_m).
struct ErrorSeries {
  std::string name;
  std::vector<double> t_s, value_m;
  std::string color;
};
PlotSpec horizontal_error_plot(const std::string& title, const std::vector<ErrorSeries>& series);

/// Empirical CDF of the horizontal error of each series (value_m used; t_s ignored).
PlotSpec error_cdf_plot(const std::string& title, const std::vector<ErrorSeries>& series);

/// Satellites used and rejected per output epoch.
PlotSpec satellites_plot(const std::vector<double>& t_s, const std::vector<double>& used,
                         const std::vector<double>& rejected);

/// ZUPT flag per output epoch (0/1) and the fraction of ZUPT epochs in a moving window of window_s seconds.
PlotSpec zupt_plot(const std::vector<double>& t_s, const std::vector<double>& zupt, double window_s);

/// Outage study: RMS across windows vs time since the outage started (forward, and smoothed if given).
PlotSpec outage_rms_plot(const std::string& title, const std::vector<double>& t_since_s,
                         const std::vector<double>& rms_forward_m, const std::vector<double>& rms_smoothed_m);

/// Monte Carlo: the average horizontal NEES over the runs against time, forward and (if given) smoothed, with the
/// two-sided 95 % band of the average (χ²(2M)/M; docs/consistency.md §1).
PlotSpec montecarlo_nees_plot(const std::string& title, const std::vector<eval::McEpochStats>& forward,
                              const std::vector<eval::McEpochStats>& smoothed);

/// Monte Carlo (seed 000 Figs. 4-5): the sample σ of the error across the runs against the filter's σ (√ of the mean
/// P) for north and east, or for yaw [deg] with `yaw`.
PlotSpec montecarlo_sigma_plot(const std::string& title, const std::vector<eval::McEpochStats>& epochs, bool yaw);

/// Monte Carlo (seed 000 Fig. 6): RMS horizontal error across the runs against the distance walked, with the line
/// of 3 % of the distance.
PlotSpec montecarlo_distance_plot(const std::string& title, const std::vector<eval::McEpochStats>& forward,
                                  const std::vector<eval::McEpochStats>& smoothed);

}  // namespace pednav::io
