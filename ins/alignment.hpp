// SPDX-License-Identifier: BSD-2-Clause
// Initial alignment: stillness check, coarse levelling (roll, pitch) and gyro bias from a stationary period,
// heading from configuration, magnetometer or later GNSS (docs/ins.md §6; Groves 2013 §5.6.2).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/expected.hpp"
#include "ins/imu.hpp"
#include "ins/nav_state.hpp"

namespace pednav::ins {

/// Thresholds of the stillness check over the levelling window.
struct StillnessOptions {
  double max_gyro_std_radps = 0.05;    ///< per-axis standard deviation of the rate [rad/s]
  double max_accel_std_mps2 = 0.15;    ///< per-axis standard deviation of the specific force [m/s^2]
  /// | |mean f| - |g| | allowed [m/s^2]: a unit or scale check. 1.5 m/s² (≈ 150 mg) admits the zero-g offsets of
  /// consumer accelerometers (tens of mg, up to ~100 mg on some axes), which a sensor nobody calibrated brings.
  double max_gravity_error_mps2 = 1.5;
  double min_duration_s = 0.5;         ///< shortest usable window [s]
};

/// Result of coarse levelling over a stationary window.
struct Levelling {
  double roll = 0.0;                                      ///< [rad]
  double pitch = 0.0;                                     ///< [rad]
  Eigen::Vector3d mean_f_ib_b = Eigen::Vector3d::Zero();  ///< [m/s^2]
  Eigen::Vector3d mean_omega_ib_b = Eigen::Vector3d::Zero();  ///< [rad/s]
  Eigen::Vector3d gyro_std_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_std_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_b = Eigen::Vector3d::Zero();  ///< mean rate minus the Earth rate (with the given yaw) [rad/s]
  double duration_s = 0.0;
  int samples = 0;
};

/// Coarse levelling over samples[0..count) (GPST-ordered) at ECEF position p_eb_e [m], assuming yaw_rad for
/// the Earth-rate part of the gyro bias. Error (naming the failed check and its value) if the window is not still.
/// Roll = atan2(-f_y, -f_z), pitch = atan2(f_x, sqrt(f_y^2 + f_z^2)) (Groves 2013 eq. 5.101 form).
Expected<Levelling> coarse_level(const std::vector<ImuSample>& samples, const Eigen::Vector3d& p_eb_e,
                                 double yaw_rad = 0.0, const StillnessOptions& options = {});

/// Normalized distance of a still window's gyro-bias estimate (lv.gyro_bias_b) from the turn-on prior N(0, σ_b0² I):
/// d² = |b|² / (σ_b0² + ARW² / T), T = lv.duration_s (docs/ins.md §6, eq. 6.1). A detected stance is not always static
/// (a foot that rolls at 1 deg/s before its first step); a d² beyond a χ²(3) quantile says the window moved and its
/// mean rate is not the bias. gyro_bias_initial_radps [rad/s] > 0, gyro_arw [rad/sqrt(s)] >= 0.
double still_gyro_bias_d2(const Levelling& lv, double gyro_bias_initial_radps, double gyro_arw);

/// A navigation state at rest at p_eb_e [m] (ECEF), time t (GPST), with attitude from roll, pitch, yaw [rad]
/// (R_e_b = R_e_n(lat, lon) R_n_b(roll, pitch, yaw)).
NavState nav_state_at_rest(GpsTime t, const Eigen::Vector3d& p_eb_e, double roll, double pitch, double yaw);

/// Heading [rad] from a magnetometer vector m_b (any unit; `initial.heading: magnetometer`, fusion/engine.cpp) at the
/// given roll/pitch [rad] plus the magnetic
/// declination [rad] (east positive): yaw = atan2(-m_y', m_x') + declination with m' levelled into the n-frame.
double heading_from_magnetometer(const Eigen::Vector3d& m_b, double roll, double pitch, double declination_rad);

}  // namespace pednav::ins
