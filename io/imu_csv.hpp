// SPDX-License-Identifier: BSD-2-Clause
// Generic IMU CSV reader driven by a column map (docs/ins.md §7 and docs/configuration.md "IMU log format").
// Messy logs: duplicate time stamps dropped and counted, out-of-order time is an error with file:line, gaps
// reported and bridged up to a limit, NaN/empty fields and saturated samples reported, unit mistakes caught.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "core/time.hpp"
#include "ins/imu.hpp"

namespace pednav::io {

/// How one IMU CSV log maps onto ImuSample (all conversions to SI happen in the reader).
struct ImuFormat {
  std::string name;                 ///< preset name or "inline"
  char delimiter = ',';
  int header_lines = 1;             ///< lines skipped before the data
  // Time.
  std::string time_base = "relative";  ///< gps_sow | gpst_unix | relative | index
  int time_column = 0;                 ///< 0-based column (unused for base index)
  double time_scale_s = 1.0;           ///< seconds per time unit of the column (key time.unit: s | ms | us | ns)
  int gps_week = -1;                   ///< week of gps_sow time stamps (required for gps_sow)
  std::optional<GpsTime> start_epoch;  ///< epoch of relative time 0 / index 0; none: GPS week 0, tow = log seconds
  double index_rate_hz = 0.0;          ///< sample rate for base index
  // Sensors.
  std::array<int, 3> gyro_columns{1, 2, 3};
  std::array<int, 3> accel_columns{4, 5, 6};
  Eigen::Vector3d gyro_signs = Eigen::Vector3d::Ones();
  Eigen::Vector3d accel_signs = Eigen::Vector3d::Ones();
  std::string gyro_unit = "rad_per_s";  ///< rad_per_s | deg_per_s | rad | deg   (rad/deg = increments per sample)
  std::string accel_unit = "mps2";      ///< mps2 | g | mps                      (mps = increments per sample)
  Eigen::Matrix3d R_b_s = Eigen::Matrix3d::Identity();  ///< mounting: sensor axes -> IMU body frame
  Eigen::Vector3d mounting_rpy_deg = Eigen::Vector3d::Zero();  ///< the angles R_b_s was read from [deg] (written back)
  /// Optional stance-label column (0 = moving, 1 = stance; e.g. reference or oracle zero-velocity labels), read
  /// into ImuLog::stance for `zupt.detector: labels`; -1 = none.
  int stance_column = -1;
  /// Optional magnetometer columns (sensor axes, any unit: only the direction is used), read into ImuLog::mag_b in
  /// the IMU body frame (same signs convention and mounting as the gyro); mag_columns[0] = -1: none.
  std::array<int, 3> mag_columns{-1, -1, -1};
  Eigen::Vector3d mag_signs = Eigen::Vector3d::Ones();
  double mag_scale_to_ut = 1.0;  ///< µT per unit of the columns (key mag.unit: ut | gauss | nt | mgauss)
  double gyro_full_scale = 0.0;   ///< [rad/s] per axis, 0 = not checked
  double accel_full_scale = 0.0;  ///< [m/s^2] per axis, 0 = not checked
  // Checks.
  double max_gap_s = 0.1;         ///< longest gap that is bridged (linear interpolation by the integrator)
  double gap_factor = 1.8;        ///< a gap is a time step > gap_factor x median step
  /// Allowed | |f_rest| - 9.8 | before the unit check fails [m/s^2]. Every unit mistake moves |f_rest| by a factor
  /// (g: 1/9.8, ft/s^2: 3.28, mg or cm/s^2: ~100); a MEMS accelerometer's own turn-on bias and scale error do not
  /// (Crista-class 30 mg + 1 %: σ ≈ 0.31 m/s^2, so 0.6 rejected about 1 IMU in 20). Between 0.6 m/s^2
  /// (kRestWarning_mps2, imu_csv.cpp) and this limit the log loads with a warning.
  double rest_tolerance_mps2 = 2.0;

  /// Every problem at once, empty when valid.
  std::vector<std::string> problems() const;
};

/// What the reader found in a log.
struct ImuLogReport {
  long rows = 0;                 ///< data rows read (after the header)
  long samples = 0;              ///< samples kept
  long duplicates_dropped = 0;   ///< rows whose time equals the previous row's (dt = 0)
  long duplicates_differing = 0; ///< ... of which the values differ from the kept row
  long bad_rows = 0;             ///< rows dropped for NaN / empty / unparsable fields
  long first_bad_line = 0;       ///< file line of the first such row (1-based), 0 = none
  long truncated_rows = 0;       ///< a last row without a line end (file cut off): dropped, its numbers may be cut
  long saturated_samples = 0;    ///< samples with any axis at >= 99.9 % of the configured full scale
  long above_full_scale = 0;     ///< samples beyond the configured full scale (impossible: the range setting is wrong)
  long gaps = 0;                 ///< time steps longer than gap_factor x median step
  double longest_gap_s = 0.0;
  long longest_gap_line = 0;
  double median_dt_s = 0.0;
  double rate_hz = 0.0;          ///< 1 / median step
  double duration_s = 0.0;       ///< last - first kept sample
  double rest_f_norm_mps2 = 0.0; ///< mean |f| over the stillest 0.5 s window
  double rest_window_start_s = 0.0;  ///< its start, seconds after the first sample
  double max_gyro_norm_radps = 0.0;
  double max_accel_norm_mps2 = 0.0;
  std::vector<std::string> warnings;  ///< human-readable notes (saturation, NaN rows, differing duplicates, ...)
};

/// A loaded IMU log: samples in GPST order, IMU body frame, SI units.
struct ImuLog {
  std::vector<ins::ImuSample> samples;
  std::vector<uint8_t> stance;  ///< per kept sample 0/1 when the format has a stance column, else empty
  std::vector<Eigen::Vector3d> mag_b;  ///< per kept sample, the magnetic field in the body frame [µT]; else empty
  ImuLogReport report;
};

/// Read an IMU CSV file with the given format.
Expected<ImuLog> read_imu_csv(const std::string& path, const ImuFormat& format);
/// Parse IMU CSV text; `source_name` names it in messages ("name:line: ...").
Expected<ImuLog> parse_imu_csv(const char* data, size_t size, const std::string& source_name, const ImuFormat& format);

/// Names of the built-in format presets (their YAML is in datasets/imu_formats/<name>.yaml).
std::vector<std::string> imu_format_preset_names();
/// The YAML text of a built-in preset (identical to datasets/imu_formats/<name>.yaml); empty if unknown.
std::string imu_format_preset_yaml(const std::string& name);

}  // namespace pednav::io
