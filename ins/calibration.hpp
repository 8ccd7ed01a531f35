// SPDX-License-Identifier: BSD-2-Clause
// Self-calibration of an IMU log (docs/ins.md §10): what a log says about its own sensor and gait, with no prior
// from a data sheet. Still periods are found by a variance test against the log's own noise floor; from them come
// the gyro bias at the start, the white-noise densities (ARW, VRW) and the gravity direction in the sensor frame
// (which axis is up, the mounting tilt). Also the true sample rate and its jitter, repeated samples, saturation
// plateaus, and the gait (footfalls of the instrumented foot, cadence, stance share, peak rates). Pure: no I/O.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "ins/imu.hpp"
#include "ins/imu_spec.hpp"

namespace pednav::ins {

struct CalibrationOptions {
  double window_s = 0.5;  ///< variance windows (non-overlapping) [s]
  /// A window is still when its gyro and accelerometer variances (sum over the axes) are at most this factor times
  /// the log's floor (the 2nd percentile of the window variances: a log whose still share is a few per cent still
  /// sets it): for 100 samples the sample variance of white noise scatters by ±14 % (1σ), so 4 leaves room for the
  /// scatter and a slowly drifting bias, and none for a foot that rolls or sways.
  double still_variance_factor = 4.0;
  double floor_percentile = 0.02;
  /// ... and its motion below these absolute bounds, on the scatter of its 0.1-s block means (the motion band below
  /// 5 Hz; white noise averages out, so a noisy sensor at a high rate is not called moving): a log that never stands
  /// still has a floor set by its slowest motion, not by the sensor. 0.05 rad/s (3 °/s) and 0.3 m/s² are far below a
  /// foot's roll or sway.
  double max_still_gyro_std_radps = 0.05;
  double max_still_accel_std_mps2 = 0.3;
  double block_s = 0.1;
  /// | |mean f| − g | of a still window [m/s²]: rejects constant-acceleration motion and wrong units, admits a
  /// consumer accelerometer's zero-g offset (≈ 150 mg; the simulated unknown sensor's draws reach 50 mg).
  double max_gravity_error_mps2 = 1.5;
  double min_still_s = 1.0;             ///< shortest still period used for the bias [s]
  /// The bias window turns (docs/ins.md eq. 10.2) when the accelerometer's rate of the gravity direction is nearer
  /// the rate its mean gyro reading would give than zero (k > moving_k) and the two are told apart (the predicted
  /// rate at least moving_min_snr of the measured rate's standard error).
  double moving_k = 0.5;
  double moving_min_snr = 3.0;
  double swing_rate_radps = 2.0;        ///< a footfall's swing peaks above this |ω| [rad/s] (foot: 3–15 rad/s)
  double min_stride_s = 0.4;            ///< swing peaks closer than this are one swing [s]
  double stance_rate_radps = 0.5;       ///< gait: samples below this |ω| (and |f| within 2 m/s² of g) count as stance
};

/// A run of still windows: samples [begin, end), start time and length.
struct StillPeriod {
  std::size_t begin = 0, end = 0;
  double t0_s = 0.0;        ///< seconds from the log's first sample
  double duration_s = 0.0;
};

struct ImuCalibration {
  std::size_t samples = 0;
  double duration_s = 0.0;
  // Timing.
  double rate_hz = 0.0;          ///< 1 / median interval
  double dt_median_s = 0.0;
  double dt_jitter_s = 0.0;      ///< RMS deviation of the intervals from the median (gaps excluded)
  long gaps = 0;                 ///< intervals longer than 1.5 median intervals
  long repeated_samples = 0;     ///< samples equal to the previous one in all six channels (a stalled logger)
  // Ranges and saturation.
  Eigen::Vector3d gyro_abs_max_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_abs_max_mps2 = Eigen::Vector3d::Zero();
  double gyro_p99_radps = 0.0;   ///< 99th percentile of |ω|
  double accel_p99_mps2 = 0.0;   ///< 99th percentile of |f|
  double gyro_plateau_radps = 0.0;   ///< a value the log sits on for >= 3 samples at its largest |ω_i| (0: none)
  double accel_plateau_mps2 = 0.0;
  long gyro_saturated_samples = 0, accel_saturated_samples = 0;
  // Still periods (variance test).
  std::vector<StillPeriod> still;
  double still_s = 0.0;          ///< total still time
  double gyro_var_floor = 0.0;   ///< floor of the window variances (sum over axes) [rad²/s²]
  double accel_var_floor = 0.0;  ///< [m²/s⁴]
  // From the still periods.
  bool bias_estimated = false;   ///< a still period of >= min_still_s exists
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();     ///< mean rate of the first long still period (Earth rate included)
  Eigen::Vector3d gyro_bias_sd_radps = Eigen::Vector3d::Zero();  ///< its standard error (white noise)
  double bias_window_t0_s = 0.0, bias_window_s = 0.0;            ///< where it was taken
  /// Does the bias window turn (docs/ins.md eq. 10.2)? The rate ġ of the unit specific force over the window (least
  /// squares, sensor axes) against p = ū × ω̄, the rate at which the mean gyro reading would turn it if all of that
  /// reading were motion: k = ġ·p / p·p is 0 for a bias (gravity stays put in the sensor axes) and 1 for a rotation.
  /// Only the part of ω̄ across gravity is seen; a turn about the vertical is not.
  double bias_window_rotation_k = 0.0;
  double bias_window_tilt_rate_radps = 0.0;       ///< |ġ| [rad/s]
  double bias_window_predicted_rate_radps = 0.0;  ///< |p| [rad/s]
  double bias_window_tilt_rate_sd_radps = 0.0;    ///< standard error of each component of ġ [rad/s]
  bool bias_window_moving = false;  ///< k > moving_k and |p| > moving_min_snr × sd: the mean rate is not a bias
  bool noise_estimated = false;
  Eigen::Vector3d gyro_noise_density = Eigen::Vector3d::Zero();   ///< [rad/s/√Hz] = ARW [rad/√s]
  Eigen::Vector3d accel_noise_density = Eigen::Vector3d::Zero();  ///< [m/s²/√Hz] = VRW [m/s/√s]
  bool gravity_estimated = false;  ///< a still period of any length exists (up_b … tilt_deg below)
  Eigen::Vector3d up_b = Eigen::Vector3d::Zero();  ///< unit specific force at rest (points up), sensor axes
  double gravity_mps2 = 0.0;     ///< |mean f| at rest
  std::string up_axis;           ///< the sensor axis closest to up: "+x" … "-z"
  double tilt_deg = 0.0;         ///< angle between up and that axis
  // Gait.
  long footfalls = 0;            ///< swing peaks of the instrumented foot (strides)
  double stride_cadence_per_min = 0.0;  ///< footfalls per minute over the walking span
  double stance_share = 0.0;     ///< share of the walking span's samples that are slow and near 1 g
  double walking_s = 0.0;        ///< first to last swing peak [s]
  std::vector<std::string> warnings;  ///< what could not be estimated or looks wrong, one line each
};

/// Calibrate from time-ordered samples (at least 2; rates in rad/s, specific force in m/s²).
ImuCalibration calibrate_imu(const std::vector<ImuSample>& samples, const CalibrationOptions& options = {});

}  // namespace pednav::ins

namespace pednav::ins {

/// How `imu.spec: auto` turns a calibration into the filter's IMU model (docs/ins.md §10.2). The floors model what a
/// foot-mounted IMU's error per step is dominated by and the sensor's white noise does not describe (rates to
/// 10 rad/s, impacts to 10 g: scale, misalignment, g-sensitivity, vibration); chosen on the tuning subset of the
/// PyShoe trials (docs/results.md), they equal the process noise of PyShoe's EKF.
struct AutoSpecOptions {
  double gyro_noise_floor = 2.12 * kAutoDegToRad / 60.0;  ///< ARW floor [rad/√s] (2.12 °/√h)
  double accel_noise_floor = 2.12 / 60.0;                  ///< VRW floor [m/s/√s] (2.12 m/s/√h)
  /// The turn-on gyro bias σ covers the bias the first still period measured (|b| per axis, at least this floor):
  /// the run starts from that bias when the period is still, and a prior narrower than |b| would call the
  /// measurement impossible (docs/ins.md eq. 6.1). A window the accelerometer shows turning
  /// (ImuCalibration::bias_window_moving, eq. 10.2) measured motion, not bias: the floor alone.
  double gyro_bias_initial_floor = 0.02 * kAutoDegToRad;   ///< [rad/s] (0.02 °/s = 72 °/h)
  double gyro_bias_instability = 10.0 * kAutoDegToRad / 3600.0;  ///< [rad/s] (10 °/h, a MEMS gyro's order)
  double gyro_bias_tau_s = 100.0;
  double accel_bias_initial = 5e-3 * 9.80665;              ///< [m/s²] (5 mg: not observable at rest)
  double accel_bias_instability = 0.1e-3 * 9.80665;        ///< [m/s²] (0.1 mg)
  double accel_bias_tau_s = 100.0;
  static constexpr double kAutoDegToRad = 3.14159265358979323846 / 180.0;
};

/// The IMU model of `imu.spec: auto`: the measured noise densities (at least the floors), the turn-on gyro bias σ
/// covering the measured bias (unless its window turned), generic MEMS bias stability, no scale-factor prior, and the ranges of any saturation
/// plateau found (else unknown: 0). Without a still period (calibration.noise_estimated false) the floors and
/// gyro_bias_initial_floor are used.
ImuSpec spec_from_calibration(const ImuCalibration& calibration, const AutoSpecOptions& options = {});

/// `zupt.shoe_threshold: auto` (docs/zupt.md §6): γ = the statistic's level at rest + a motion allowance. The level at
/// rest is the rest_quantile of T over the calibration's still periods (the sensor's own noise in the units of the
/// configured σ's: a noisy sensor at a high rate sits far above a quiet one), or the 5th percentile of T when the log
/// has no still period. The allowance is the motion a stance may keep (a foot rolling over its sole) in the same
/// units: with the default σ's (0.5 m/s², 0.1 rad/s) 2.5 admits about 0.16 rad/s of steady rotation.
struct AutoThresholdOptions {
  double rest_quantile = 0.99;
  /// Chosen with kAutoAdaptiveFactor and kAutoAdaptiveMinPeakDegPerS by leave-one-session-out cross-validation on
  /// the 24 PyShoe trials (scripts/pyshoe_loso; docs/zupt.md §6, docs/results.md "Out of the box").
  double motion = 2.5;
  /// The two-class split (docs/zupt.md eq. 6.2): γ is raised to the boundary that best separates the log's
  /// statistic into two classes (Otsu on log10 T), at most to this cap; 0 = off (γ = rest + motion). The split is
  /// where a gait's stance and swing part; on slow, rolling or crawling motion it lies far above rest + motion and
  /// recovers the stances the fixed allowance misses. Chosen by leave-one-session-out cross-validation with the
  /// other auto knobs (scripts/pyshoe_loso).
  double two_class_cap = 10.0;
};
/// The boundary between the two classes of a positive statistic (T, e.g. SHOE) that maximizes the between-class
/// variance of log10 T (Otsu 1979) over a histogram of `bins` equal bins between the smallest and largest log10 T
/// (T clamped at 1e-6); 0 when the statistic has fewer than two distinct values.
double two_class_split(const std::vector<double>& statistic, int bins = 200);
/// The gait-adaptive raise (docs/zupt.md §1) that `zupt.shoe_threshold: auto` switches on unless its keys are given:
/// threshold max(γ, factor × the smallest T within ±window/2) next to a swing whose peak rate reaches the minimum.
inline constexpr double kAutoAdaptiveFactor = 4.0;
inline constexpr double kAutoAdaptiveWindowS = 1.0;
inline constexpr double kAutoAdaptiveMinPeakDegPerS = 360.0;
struct AutoThreshold {
  double rest = 0.0;       ///< T at rest (the rest_quantile over the still periods)
  double threshold = 0.0;  ///< γ = max(rest + motion, min(split, cap))
  bool from_still = false; ///< rest level from still periods (else the 5th percentile of T)
  double split = 0.0;      ///< two_class_split of the whole log's T (0: not used)
  bool from_split = false; ///< γ is the (capped) split, above rest + motion
  double cap = 0.0;        ///< the cap the split was held to (AutoThresholdOptions::two_class_cap; 0: off)
};
AutoThreshold auto_shoe_threshold(const std::vector<double>& shoe_statistic, const ImuCalibration& calibration,
                                  const AutoThresholdOptions& options = {});

}  // namespace pednav::ins
