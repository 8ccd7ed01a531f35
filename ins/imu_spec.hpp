// SPDX-License-Identifier: BSD-2-Clause
// IMU noise and error specification (SI inside) and named presets (docs/ins.md §5 cites the datasheets).
#pragma once

#include <string>
#include <vector>

#include "core/expected.hpp"

namespace pednav::ins {

/// Stochastic model of one IMU. All SI: rad, s, m. Bias model per axis: a first-order Gauss-Markov process
/// with steady-state sigma `*_bias_instability` and correlation time `*_bias_tau_s` (tau <= 0: no GM part),
/// whose driving noise is added to the random walk `*_bias_rw` (docs/error_state.md §4).
struct ImuSpec {
  std::string name;
  double gyro_arw = 0.0;                ///< angle random walk [rad/sqrt(s)] (= gyro white-noise density, rad/s/sqrt(Hz))
  double accel_vrw = 0.0;               ///< velocity random walk [m/s/sqrt(s)] (= accel noise density, m/s^2/sqrt(Hz))
  double gyro_bias_instability = 0.0;   ///< GM steady-state sigma [rad/s]
  double gyro_bias_tau_s = 0.0;         ///< GM correlation time [s]; <= 0 disables the GM part
  double gyro_bias_rw = 0.0;            ///< bias random walk [rad/s/sqrt(s)]
  double gyro_bias_initial = 0.0;       ///< turn-on bias sigma [rad/s] (initial covariance)
  double accel_bias_instability = 0.0;  ///< [m/s^2]
  double accel_bias_tau_s = 0.0;        ///< [s]
  double accel_bias_rw = 0.0;           ///< [m/s^2/sqrt(s)]
  double accel_bias_initial = 0.0;      ///< [m/s^2]
  double gyro_scale_sigma = 0.0;        ///< scale-factor error sigma [-] (1e-6 = 1 ppm)
  double accel_scale_sigma = 0.0;       ///< [-]
  double scale_tau_s = 0.0;             ///< scale-factor GM correlation time [s]; <= 0: random constant
  /// g-sensitive gyro error: σ of each element of G in ω_measured = … + G f [rad/s per m/s^2] (random constants);
  /// 0 = not modelled. > 0 gives the filter 9 consider states for G (docs/error_state.md §5).
  double gyro_g_sensitivity = 0.0;
  double gyro_range = 0.0;              ///< full scale [rad/s] (0 = unknown; saturation not checked)
  double accel_range = 0.0;             ///< full scale [m/s^2]

  /// Every problem at once ("gyro_arw must be >= 0"), empty when valid.
  std::vector<std::string> problems() const;
};

/// A preset by name: "crista", "hg1700", "gx5_25", "ngimu" (docs/ins.md §5).
Expected<ImuSpec> imu_spec_preset(const std::string& name);
/// Names of all presets.
std::vector<std::string> imu_spec_preset_names();

}  // namespace pednav::ins
