// SPDX-License-Identifier: BSD-2-Clause
// GNSS outage studies (seed 004 section "GPS/INS/ZUPTs integrated results", Figures 14-17): placement of the
// outage windows, which satellites a partial outage keeps, and the aggregation of the per-window position errors
// into the error as a function of time since the outage started (RMS across windows, seed 004 Figure 17).
// Pure functions: no I/O.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "core/time.hpp"

namespace pednav::eval {

/// One simulated GNSS outage: GNSS is removed (full) or reduced (partial) in [start, start + duration_s).
struct OutageWindow {
  GpsTime start;            ///< GPST
  double duration_s = 0.0;  ///< [s]
  GpsTime end() const { return start.plus_s(duration_s); }
  bool contains(GpsTime t) const { return !(t < start) && t < end(); }
};

/// `count` windows of `duration_s` placed evenly in [from, to] (GPST): the span is cut into `count` equal slots
/// and each window is centred in its slot. Fails when the windows do not fit (message gives the available span).
Expected<std::vector<OutageWindow>> place_windows_evenly(GpsTime from, GpsTime to, int count, double duration_s);

/// Where a reference trajectory can score a solution: its epochs (GPST, increasing) and the largest gap between two
/// epochs that is still bridged (eval::CompareOptions::max_interp_gap_s: the reference is interpolated across it).
struct ReferenceCoverage {
  std::vector<GpsTime> epochs;
  double max_gap_s = 1.5;
  /// Seconds of [start, end] covered: the union of the bridged gaps between consecutive epochs, clipped.
  double covered_s(GpsTime start, GpsTime end) const;
};

/// `count` windows of `duration_s` in [from, to] where a reference covers them (issue 49 item 8): the span is cut into
/// `count` equal slots as in place_windows_evenly, and in each slot the window starts at the whole second (counted
/// from `from`) whose window the reference covers longest; ties go to the start nearest the slot's centred window.
/// When the reference covers every centred window this is place_windows_evenly. A slot the reference does not reach
/// keeps its centred window (covered 0 s: the caller reports it as unscorable). Fails as place_windows_evenly does.
Expected<std::vector<OutageWindow>> place_windows_covered(GpsTime from, GpsTime to, int count, double duration_s,
                                                          const ReferenceCoverage& reference);

/// Explicit windows (start times in GPST); fails if a window overlaps the next one or the starts are not increasing.
Expected<std::vector<OutageWindow>> explicit_windows(std::vector<GpsTime> starts, double duration_s);

/// A satellite usable at one epoch, as a partial outage sees it.
struct SatCandidate {
  int id = 0;                  ///< caller's key (e.g. index into the epoch's satellites)
  double elevation_rad = 0.0;  ///< at the receiver
  double cn0_dbhz = 0.0;       ///< NaN counts as the weakest
};

enum class KeepBy {
  kElevation,  ///< drop the lowest-elevation satellite while more than N remain (seed 004)
  kCn0,        ///< drop the weakest (lowest C/N0) satellite while more than N remain
};

/// Ids of the satellites a partial outage keeps: at most `keep` of the candidates, the highest (or strongest).
/// Ties are broken by id so the choice is deterministic. keep <= 0 keeps none (a full outage).
std::vector<int> select_kept_satellites(std::vector<SatCandidate> candidates, int keep, KeepBy by);

/// Position error of one run inside one window: samples at times since the window's start.
struct WindowErrors {
  OutageWindow window;
  std::vector<double> t_since_s;     ///< time since the outage started [s], increasing
  std::vector<double> horizontal_m;  ///< horizontal error [m] at those times
  /// The solution's own horizontal 1σ √(P_nn + P_ee) [m] at those times; empty when the caller has none.
  std::vector<double> sigma_horizontal_m;
};

/// Per-window figures for outages.csv.
struct WindowStats {
  int samples = 0;
  double max_m = 0.0;       ///< maximum horizontal error inside the window [m]
  double end_m = 0.0;       ///< horizontal error at the last sample of the window [m]
  double end_t_since_s = 0.0;
  /// The solution's horizontal 1σ at the sample of the maximum error and at the last sample [m]; NaN without σ.
  double sigma_at_max_m = NAN;
  double end_sigma_m = NAN;
};

/// Maximum and end error of one window (samples == 0 when the window has no sample).
WindowStats window_stats(const WindowErrors& w);

/// Seed 004 Figure 17: RMS of the horizontal error across windows as a function of time since the outage started.
struct RmsVsTime {
  std::vector<double> t_since_s;  ///< bin centres k * bin_s [s]
  std::vector<double> rms_m;      ///< sqrt(mean over windows of the squared error) [m]
  std::vector<int> n_windows;     ///< windows with a sample in the bin
};

/// Bin every window's samples to the nearest multiple of bin_s (one sample per window and bin: the one nearest to
/// the bin centre, within bin_s / 2) and take the RMS across windows. Bins without any sample are omitted.
RmsVsTime rms_vs_time(const std::vector<WindowErrors>& windows, double bin_s);

/// Empirical CDF of non-negative errors: sorted values and the fraction of samples <= each value (i / n).
struct Cdf {
  std::vector<double> value;
  std::vector<double> fraction;
};
Cdf empirical_cdf(std::vector<double> values);

}  // namespace pednav::eval
