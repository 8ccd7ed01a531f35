// SPDX-License-Identifier: BSD-2-Clause
// The antenna states of the tight coupling (EngineOptions::antenna_state, docs/carrier.md §10). A backpack or head
// antenna moves with the walker's body, smoothly, while the foot IMU stops and swings: the antenna gets its own
// position and velocity (white acceleration, eq. 10.1) and is tied to the foot by the non-rigid arm and the
// stride-average velocity at every rover epoch (eq. 10.2); code, Doppler and phase then measure the antenna states
// (eq. 10.3), so that the phase, which needs an antenna whose motion it can follow from epoch to epoch, sees one.
// Internal to the engine; no file I/O, no logging.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "fusion/engine_types.hpp"
#include "fusion/error_state_filter.hpp"
#include "fusion/lever_arm.hpp"
#include "fusion/stride_velocity.hpp"
#include "ins/imu.hpp"
#include "ins/zupt_detector.hpp"

namespace pednav::fusion {

/// Columns of the tie's Jacobian: the foot's position, velocity and attitude errors, then the antenna's position and
/// velocity errors (ECEF) and the arm's error (the foot's heading frame: forward, right, down).
enum AntennaTieColumn {
  kTieFootPos = 0, kTieFootVel = 3, kTieFootAtt = 6, kTieAntPos = 9, kTieAntVel = 12, kTieArmError = 15
};

/// Eq. 10.2 at the nominal state: h(x) = [p_a − p − arm(R_e_b, l_h + b); v_a − v̄] with the arm of eq. 14.1 whose
/// heading-frame part carries the arm's error b, v̄ the stride-average foot velocity (or, before a gait cycle exists,
/// the foot's own velocity v), residual r = 0 − h(x̂), the Jacobian of h w.r.t. the 18 error columns of
/// AntennaTieColumn and the noise: the arm's variation C_pos and the body-vs-stride velocity C_vel (ECEF).
/// arm: eq. 14.1 at l_h + b̂; d_arm_d_b_e: ∂arm_e/∂l_h (the heading frame's axes in ECEF).
struct AntennaTieRows {
  Eigen::Matrix<double, 6, 1> residual = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 18> J = Eigen::Matrix<double, 6, 18>::Zero();
  Eigen::Matrix<double, 6, 6> cov_meas = Eigen::Matrix<double, 6, 6>::Zero();
};
AntennaTieRows antenna_tie_rows(const Eigen::Vector3d& p_e, const Eigen::Vector3d& v_e, const LeverArm& arm,
                                const Eigen::Matrix3d& d_arm_d_b_e, const std::optional<Eigen::Vector3d>& v_stride_e,
                                const Eigen::Vector3d& ant_p_e, const Eigen::Vector3d& ant_v_e,
                                const Eigen::Matrix3d& C_pos_e, const Eigen::Matrix3d& C_vel_e);

/// ∂arm_e/∂l_h of eq. 14.1: the columns are the foot's heading-frame axes (forward, right, down) in ECEF.
Eigen::Matrix3d arm_heading_axes_e(const Eigen::Matrix3d& R_e_n, const Eigen::Matrix3d& R_e_b);

/// The antenna noise of the options in ECEF at p_e: the arm's walking variation (antenna_sigma_*, at mid-stance
/// antenna_stance_sigma_*) and the body vs stride-average velocity (antenna_stride_velocity_sigma_*, or
/// antenna_velocity_sigma_* without a stride).
Eigen::Matrix3d antenna_position_cov_e(const EngineOptions& o, const Eigen::Vector3d& p_e, bool mid_stance = false);
Eigen::Matrix3d antenna_velocity_cov_e(const EngineOptions& o, const Eigen::Vector3d& p_e, bool stride);

/// The lever arm of eq. 14.1 at the filter's nominal state (with antenna states: its heading part plus the estimated
/// arm error).
LeverArm filter_lever_arm(const ErrorStateFilter& f, const EngineOptions& o);

/// Start the antenna states from the foot: p + arm, the foot's velocity (or v̄), the foot's position covariance plus
/// C_pos (after an initialization or a re-initialization of the filter).
void init_antenna_from_foot(ErrorStateFilter& f, const EngineOptions& o, const StrideVelocity& stride);

/// The tie of eq. 10.2 as a filter update, at mid-stance (the arm's σ antenna_stance_sigma_*) or elsewhere in the
/// gait (antenna_sigma_*). The consistency gate of eq. 10.4: a half (position, velocity) whose normalized innovation
/// d² exceeds the χ²(3) quantile at fault_probability has its noise inflated by d²/χ² — the foot INS and the antenna
/// the phase holds disagree beyond both σ's, and a tie at its nominal σ would drag the antenna to a foot that is
/// elsewhere (or the foot to it); left out, the foot would lose every GNSS epoch. Counts the halves inside and beyond
/// the gate into sum. True when applied.
bool antenna_tie_update(ErrorStateFilter& f, const EngineOptions& o, const StrideVelocity& stride, bool mid_stance,
                        EngineSummary& sum);

/// Spacing of the ties while the walker stands [s]: a standing body sways slowly, so ties once per second would count
/// one offset many times as if each were new (a static antenna over-confident to centimetres, docs/carrier.md §10).
inline constexpr double kStandingTieSpacingS = 10.0;

/// The samples at which the tie is applied (ascending): the middle of every stance shorter than 2 s, and in a longer
/// stance (standing) its first sample + 0.5 s and then one every kStandingTieSpacingS until 0.5 s before its end.
std::vector<size_t> antenna_tie_samples(const std::vector<ins::ZuptDecision>& decisions,
                                        const std::vector<ins::ImuSample>& imu);

}  // namespace pednav::fusion
