// SPDX-License-Identifier: BSD-2-Clause
// Precise ECEF strapdown mechanization over one increment interval (docs/ins.md §3; Groves 2013 §5.2 and §5.5).
#pragma once

#include <Eigen/Core>

#include "ins/imu.hpp"
#include "ins/nav_state.hpp"

namespace pednav::ins {

/// Estimated IMU errors applied to the increments before mechanization. Sensor model (docs/error_state.md):
/// omega_meas = (I + diag(s_g)) omega_true + b_g + noise, f_meas = (I + diag(s_a)) f_true + b_a + noise.
struct ImuErrors {
  Eigen::Vector3d b_g = Eigen::Vector3d::Zero();  ///< gyro bias [rad/s], body frame
  Eigen::Vector3d b_a = Eigen::Vector3d::Zero();  ///< accelerometer bias [m/s^2], body frame
  Eigen::Vector3d s_g = Eigen::Vector3d::Zero();  ///< gyro scale-factor errors [-] (1e-6 = 1 ppm)
  Eigen::Vector3d s_a = Eigen::Vector3d::Zero();  ///< accelerometer scale-factor errors [-]
  /// g-sensitive gyro error: ω_measured = (I + diag s_g) ω + b_g + G_g f [rad/s per m/s^2] (docs/error_state.md §5).
  Eigen::Matrix3d G_g = Eigen::Matrix3d::Zero();
};

/// Remove estimated biases, scale factors and the g-sensitive gyro error (G_g times the corrected velocity
/// increment) from an increment (first order: the compensation terms are corrected with the same ratio as the plain
/// increments). A reference implementation for the tests: the engine corrects each sample (correct_sample) before
/// integrating, and tests/ins/test_mechanization.cpp checks that both agree.
ImuIncrement correct_increment(const ImuIncrement& inc, const ImuErrors& errors);

/// Remove estimated biases and scale factors from one sample (use this before integration when the biases
/// are large, e.g. MEMS gyros of several deg/s, so the coning/sculling terms see corrected rates).
ImuSample correct_sample(const ImuSample& sample, const ImuErrors& errors);

/// Specific-force velocity increment over the interval resolved in e [m/s]: R_e_b(t0) dv_b minus the
/// Earth-rate frame-rotation term omega_ie x R_e_b (dv_b dt - dp_b) (Groves 2013 §5.5.2). `prev` at inc.t0.
Eigen::Vector3d specific_force_increment_e(const NavState& prev, const ImuIncrement& inc);

/// One precise ECEF mechanization step from prev (at inc.t0) to inc.t1: attitude with Earth rate (exact for a
/// constant Earth rate), specific-force transformation, position from the double integral of specific force
/// plus gravity and Coriolis, velocity with J2 gravity at the mid-point and Coriolis with the mean velocity.
/// docs/ins.md eq. (3.1)-(3.5).
NavState mechanize(const NavState& prev, const ImuIncrement& inc);

}  // namespace pednav::ins
