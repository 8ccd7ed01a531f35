// SPDX-License-Identifier: BSD-2-Clause
// Monte Carlo consistency of a navigation filter (seed 000, issue 9): per output epoch across M seeded runs the
// mean error, the sample σ of the error, the mean filter σ (√P), the average NEES with its two-sided 95 % χ² band,
// and the RMS error vs distance travelled. Pure aggregation: no I/O (pipeline/montecarlo_command.cpp reads and writes).
// Definitions and how to read the figures: docs/consistency.md.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace pednav::eval {

/// One output epoch of one run: the error of the estimate and the filter's covariance of it.
struct McEpoch {
  double t_s = 0.0;                                       ///< time since the scenario start [s] (epoch key)
  double distance_m = 0.0;                                ///< route distance walked at t [m]
  Eigen::Vector3d err_ned_m = Eigen::Vector3d::Zero();    ///< position error estimate − truth, NED at the truth [m]
  Eigen::Matrix3d cov_ned_m2 = Eigen::Matrix3d::Zero();   ///< filter position covariance, NED [m²]
  double err_yaw_rad = 0.0;                               ///< yaw error estimate − truth, wrapped to (−π, π] [rad]
  double var_yaw_rad2 = 0.0;                              ///< filter yaw variance [rad²]
};

/// Carrier-phase figures of one run's forward solution at its GNSS epochs (`pednav montecarlo --carrier`,
/// docs/consistency.md §6): how often the antenna was fixed, how often a fixed antenna was off by more than a wrong-fix
/// threshold, and the antenna's horizontal NEES on its fixed epochs (cm-level σ must mean cm-level error).
struct McCarrierRun {
  int gnss_epochs = 0;             ///< output epochs at a GNSS epoch (the scored ones)
  int fixed_epochs = 0;            ///< of those, with status fixed
  int wrong_fixed_epochs = 0;      ///< fixed, with the antenna's horizontal error above the wrong-fix threshold
  double antenna_nees_sum = 0.0;   ///< Σ over the fixed epochs of e_hᵀ P_h⁻¹ e_h of the antenna (2 dof)
  double time_to_first_fix_s = -1.0;  ///< first fixed epoch since the first scored one [s]; < 0: never fixed
};

/// One run: its forward and (optional, same epochs) smoothed errors.
struct McRun {
  std::vector<McEpoch> forward;
  std::vector<McEpoch> smoothed;
  McCarrierRun carrier;  ///< zero unless the study ran with the carrier phase
};

/// The carrier-phase figures of a study (summary.json `carrier`).
struct McCarrierSummary {
  int runs = 0;
  int runs_with_fix = 0;            ///< runs with at least one fixed epoch
  int runs_with_wrong_fix = 0;      ///< runs with at least one wrong fixed epoch
  long gnss_epochs = 0, fixed_epochs = 0, wrong_fixed_epochs = 0;
  double fix_rate = 0.0;            ///< fixed / GNSS epochs over all runs
  double wrong_fix_rate = 0.0;      ///< wrong fixed / fixed epochs (0 without fixed epochs)
  double mean_antenna_nees_fixed = 0.0;  ///< mean antenna horizontal NEES over all fixed epochs (2 when honest)
  double median_time_to_first_fix_s = -1.0;  ///< over the runs with a fix (< 0: none)
  double max_time_to_first_fix_s = -1.0;
};

/// Pools the runs' carrier figures.
McCarrierSummary summarize_carrier(const std::vector<McRun>& runs);

/// Statistics of one output epoch across the runs that have it (seed 000 eq. for ē, σ̄; Bar-Shalom 2001 §5.4 NEES).
struct McEpochStats {
  double t_s = 0.0;
  int runs = 0;                                             ///< M at this epoch
  double distance_m = 0.0;                                  ///< mean route distance [m]
  Eigen::Vector3d mean_err_ned_m = Eigen::Vector3d::Zero(); ///< ē per axis [m]
  Eigen::Vector3d sample_sd_ned_m = Eigen::Vector3d::Zero();///< σ̄ per axis, (M−1) denominator [m]
  Eigen::Vector3d filter_sd_ned_m = Eigen::Vector3d::Zero();///< √(mean of P_ii) per axis [m]
  double mean_err_yaw_rad = 0.0, sample_sd_yaw_rad = 0.0, filter_sd_yaw_rad = 0.0;
  double rms_horizontal_m = 0.0;                            ///< √(mean over runs of e_N² + e_E²) [m]
  double nees_horizontal = 0.0;   ///< average over runs of e_hᵀ P_h⁻¹ e_h (2 dof)
  double nees_yaw = 0.0;          ///< average over runs of e_ψ² / P_ψψ (1 dof)
  double nees_lo_2dof = 0.0, nees_hi_2dof = 0.0;  ///< two-sided 95 % band of the average 2-dof NEES at this M
  double nees_lo_1dof = 0.0, nees_hi_1dof = 0.0;  ///< the same for 1 dof
  double inside_3sigma_fraction = 0.0;  ///< share of runs with |e_N| ≤ 3σ_N and |e_E| ≤ 3σ_E at this epoch
};

/// Whole-run summary (summary.json keys of DESIGN.md + extras).
struct McSummary {
  int runs = 0;
  int epochs = 0;                              ///< epochs with at least min_runs runs (the ones summarized)
  double nees_in_band_fraction = 0.0;          ///< share of epochs whose horizontal NEES is inside its 95 % band
  double nees_yaw_in_band_fraction = 0.0;      ///< the same for yaw
  double nees_above_band_fraction = 0.0;       ///< horizontal NEES above the band (filter optimistic)
  double nees_below_band_fraction = 0.0;       ///< below the band (filter pessimistic)
  double mean_nees_horizontal = 0.0;           ///< time average of the average NEES (2 for a consistent filter)
  double sigma_ratio_horizontal = 0.0;         ///< median over epochs of √((s_N² + s_E²)/(σ_N² + σ_E²)), s sample σ
  double sigma_ratio_yaw = 0.0;                ///< median over epochs of s_ψ / σ_ψ
  double sigma_ratio_horizontal_pooled = 0.0;  ///< √(Σ sample var N,E / Σ mean filter var N,E) over epochs
  double sigma_ratio_yaw_pooled = 0.0;         ///< the same for yaw
  double inside_3sigma_fraction = 0.0;         ///< share of (run, epoch) pairs with N and E inside 3σ
  double rms_horizontal_m = 0.0;               ///< RMS horizontal error over all runs and epochs [m]
};

/// The NEES band test per time window. The epochs of a window are not independent tests (the errors of a filter,
/// and more so of a smoother, are correlated over many epochs; a stand is one draw: docs/consistency.md §3.13), so
/// the windows show where the in-band share is lost, and how few independent tests it rests on.
struct McWindowBand {
  double from_s = 0.0, to_s = 0.0;     ///< [from, to) since the scenario start [s]
  int epochs = 0;                      ///< epochs of the summary inside the window
  double nees_in_band_fraction = 0.0;  ///< share of those epochs with the horizontal NEES inside its 95 % band
  double mean_nees_horizontal = 0.0;   ///< mean of the average NEES over those epochs (2 when consistent)
};

/// Consecutive windows of `window_s` from t = 0 to the last epoch (windows without epochs are left out).
std::vector<McWindowBand> window_bands(const std::vector<McEpochStats>& epochs, double window_s);

/// Per-epoch statistics of forward or smoothed errors (`smoothed` selects McRun::smoothed). Epochs are keyed by
/// t_s rounded to `key_resolution_s`; epochs present in fewer than `min_runs` runs are left out (min_runs >= 2).
std::vector<McEpochStats> aggregate_epochs(const std::vector<McRun>& runs, bool smoothed, int min_runs,
                                           double key_resolution_s = 1e-3);

/// Summary over the per-epoch statistics; epochs with t_s < t_from_s are left out of the fractions and ratios.
McSummary summarize(const std::vector<McEpochStats>& epochs, int runs, double t_from_s = -1e300);

/// Quantile of the χ² distribution with `dof` degrees of freedom at probability p in (0, 1), by the
/// Wilson–Hilferty transform (relative error < 1e-3 for dof ≥ 30; used with dof = M·d ≥ 100 here).
double chi_square_quantile_wh(double p, double dof);

/// Two-sided band [lo, hi] of the average NEES of M runs of a d-dof error at level `prob` (0.95):
/// M·ε̄ ~ χ²(M·d), so lo = χ²_{(1−prob)/2}(Md)/M, hi = χ²_{(1+prob)/2}(Md)/M (Bar-Shalom 2001 §5.4.2).
std::pair<double, double> average_nees_band(int runs, int dof, double prob = 0.95);

/// Standard normal quantile Φ⁻¹(p), p in (0, 1): Newton iterations on Φ(x) = erfc(−x/√2)/2 (|error| < 1e-12).
double normal_quantile(double p);

}  // namespace pednav::eval
