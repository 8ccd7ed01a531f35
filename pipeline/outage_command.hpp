// SPDX-License-Identifier: BSD-2-Clause
// `pednav outage CONFIG.yaml -o OUT`: GNSS outage study (seed 004 Figures 14-17). One run without outage, then
// one run per window with the GNSS mask applied (full outage, or partial: keep N satellites, dropping the lowest
// elevation - or weakest C/N0 - satellite while more than N remain). Errors against the configured reference, else
// against the run without outage; outages.csv, rms_vs_time.csv, summary.json and outage_rms.svg.
#pragma once

#include <string>
#include <vector>

#include "core/expected.hpp"
#include "eval/outage.hpp"
#include "io/config.hpp"

namespace pednav::pipeline {

struct OutageArgs {
  std::string out_dir;
  int windows = 5;                        ///< evenly placed windows (ignored with explicit starts)
  double duration_s = 100.0;              ///< [s]
  std::vector<double> start_tow_s;        ///< explicit window starts, GPS seconds of week (week of the run's start)
  int keep_sats = 0;                      ///< satellites kept during a window; 0 = full outage
  eval::KeepBy keep_by = eval::KeepBy::kElevation;
  double converged_sigma_horizontal_m = 1.0;  ///< convergence: horizontal 1-sigma of the run without outage [m]
  double converged_sigma_yaw_deg = 2.0;       ///< and its yaw 1-sigma [deg]
  double settle_s = 30.0;                     ///< windows start this long after convergence at the earliest [s]
  std::string against = "auto";           ///< auto | reference | run (auto: the reference when configured)
  bool plot = true;                       ///< write outage_rms.svg (gnuplot)
  int jobs = 1;                           ///< windows run in parallel
  bool write_runs = false;                ///< also write OUT/window_<k>/solution.csv (+ smoothed.csv) of every run
};

/// Figures of one kind of solution (forward or smoothed) across the windows.
struct OutageFigures {
  std::vector<eval::WindowStats> per_window;
  eval::RmsVsTime rms;
  double max_error_m = 0.0;      ///< maximum over windows of the maximum horizontal error [m]
  double max_rms_m = 0.0;        ///< maximum of the RMS-vs-time curve [m] (seed 004 Figure 17)
  double rms_at_end_m = 0.0;     ///< RMS across windows of the error at the window's end [m]
};

struct OutageResult {
  std::vector<eval::OutageWindow> windows;
  std::string against;           ///< "reference" or "run"
  OutageFigures forward, smoothed;          ///< against `against`
  OutageFigures forward_vs_run, smoothed_vs_run;  ///< against the run without outage (seed 004's method)
  bool has_smoothed = false;
  std::vector<double> sats_kept_mean;       ///< per window: mean satellites left per masked epoch
  std::vector<int> sats_kept_min, sats_kept_max;
  std::vector<long> epochs_masked;          ///< per window: engine's count of epochs emptied by the mask
  /// Per window: why the reference could not score it ("" = scored). Such a window has no sample in `forward` and
  /// `smoothed` (its figures against the run without outage remain).
  std::vector<std::string> unscored_reason;
  /// With the carrier phase (gnss.carrier: on; docs/outage.md §1.1): per window, seconds from the window's end to the
  /// first forward epoch with status fixed (NaN: none before the run ends), and the same from the window's start in
  /// the run without outage (how long that run took to be fixed there; 0 when it was fixed at the start).
  bool carrier = false;
  std::vector<double> refix_s, nominal_fix_s;
};

/// Run the study for a loaded configuration and write the outputs into args.out_dir. The study is of the tightly
/// coupled filter: a configuration of another mode runs as tc when it has the IMU log and the GNSS files.
Expected<OutageResult> run_outage_command(const io::RunConfig& config, const OutageArgs& args);

}  // namespace pednav::pipeline
