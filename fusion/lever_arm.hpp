// SPDX-License-Identifier: BSD-2-Clause
// IMU (foot) -> GNSS antenna (body) lever arm of the tightly coupled filter (docs/fusion.md §14).
//
// A backpack antenna is not rigidly attached to a foot IMU: the filter carries the offset's walking variation as
// noise (EngineOptions::antenna_sigma_*). What is fixed is its mean: a part fixed in the local level frame (the
// antenna height above the foot) and a part fixed in the foot's heading frame — the foot of a walker is beside the
// walking line, so a right-foot IMU has the body, and the antenna, about half a step width to its left in every
// direction of travel, and still so while the walker stands. Modelled as white noise, that lateral offset is a bias
// common to every epoch, which a smoother averaging a standing period turns into an over-confident error.
//
//   arm_n = l_n + l_f u_f + l_r u_r + l_d d,   u_f = (x_N, x_E, 0)/h,  u_r = (−x_E, x_N, 0)/h,  d = (0, 0, 1)   (14.1)
//
// with x = R_n_b e₁ the foot's x axis in NED and h = √(x_N² + x_E²). A rotation error φ (docs/error_state.md: the
// true attitude is exp([φ×]) R_e_b) changes x by φ_n × x, hence the heading ψ = atan2(x_E, x_N) by
//
//   δψ = φ_D − x_D (x_N φ_N + x_E φ_E) / h²,    ∂arm_n/∂ψ = l_f u_r − l_r u_f                                    (14.2)
//
// (the second term of δψ is the pitched foot's: at 60° of push-off pitch a north rotation moves the heading too).
// Pure maths: no file I/O, no logging, no allocation.
#pragma once

#include <Eigen/Core>

namespace pednav::fusion {

/// The antenna offset from the IMU, ECEF [m], and its derivative with respect to the attitude error φ (ECEF).
struct LeverArm {
  Eigen::Vector3d arm_e = Eigen::Vector3d::Zero();
  Eigen::Matrix3d d_arm_d_phi_e = Eigen::Matrix3d::Zero();
};

/// Eq. 14.1–14.2. arm_n_m: the level-frame part (NED) [m]; arm_heading_m: (forward, right, down) of the foot's
/// heading frame [m]; R_e_n at the IMU; R_e_b the IMU attitude. A foot pointing straight up or down (h < 1e-6) has
/// no heading: the heading part is then left out (and its Jacobian is zero).
LeverArm lever_arm_e(const Eigen::Vector3d& arm_n_m, const Eigen::Vector3d& arm_heading_m, const Eigen::Matrix3d& R_e_n,
                     const Eigen::Matrix3d& R_e_b);

}  // namespace pednav::fusion
