// SPDX-License-Identifier: BSD-2-Clause
// The updates of a foot at rest and of its steps: the ZUPT in form D or F (docs/fusion.md §4, seed 001 eq. 8-9) with
// the re-expression of the covariance at the new velocity (eq. 5.9), the zero angular-rate update (ZARU) over an
// all-stance interval with its optional innovation gate (§5.3), and the seed 000 step-averaged velocity update.
// Internal to the engine.
#pragma once

#include <Eigen/Core>

#include "fusion/engine_types.hpp"
#include "fusion/error_state_filter.hpp"
#include "fusion/step_velocity.hpp"
#include "ins/error_state.hpp"
#include "ins/imu.hpp"

namespace pednav::fusion {

/// The ZUPT measurement Jacobian w.r.t. the error state (velocity and attitude blocks) for the estimated
/// velocity v_e [m/s]: form F: [I 0], form D: [I [v×]] (docs/fusion.md eq. 4.3; seed 001 eq. 8-9).
Eigen::Matrix<double, 3, 6> zupt_jacobian(const Eigen::Vector3d& v_e, ZuptForm form);

/// Rows of the non-holonomic constraint of a device held in the hand (docs/fusion.md eq. 8.4) at the nominal state:
/// h(x) = [u_lᵀ v, −downᵀ v] (the cross and up rows of step_velocity_prediction at the current velocity), residual
/// r = 0 − h(x̂), Jacobian w.r.t. [δv, φ] and the noise diag(σ_cross², σ_up²).
struct HandNhcRows {
  Eigen::Vector2d residual = Eigen::Vector2d::Zero();
  Eigen::Matrix<double, 2, 6> J_dv_phi = Eigen::Matrix<double, 2, 6>::Zero();
  Eigen::Matrix2d cov_meas = Eigen::Matrix2d::Zero();
};
HandNhcRows hand_nhc_rows(const ins::NavState& nav, double sigma_cross_mps, double sigma_up_mps);

class StanceUpdater {
 public:
  explicit StanceUpdater(const EngineOptions& o);

  /// ZUPT (+ ZARU when the interval started in stance too, so neither end is at a stance edge) at the end of
  /// increment `inc`: z = 0 − v̂; form D adds the attitude coupling [v̂×] (seed 001 eq. 8); ZARU: ω − b_g − ω_ie
  /// with the interval's mean bias-corrected rate. Counts ZARU rows used and gated into `sum`.
  void zupt_update(ErrorStateFilter& f, const ins::ImuIncrement& inc, bool interval_start_stance, EngineSummary& sum);

  /// Step-averaged velocity (seed 000 eq. 3): along/cross-track/vertical average velocity of the step vs ΔL/T,
  /// applied at the stance onset that ends the step; state blocks: velocity and attitude (fusion/step_velocity.hpp).
  void step_velocity_update(ErrorStateFilter& f, const StepMeasurement& m, EngineSummary& sum);

  /// Non-holonomic constraint of a device held in the hand (docs/fusion.md eq. 8.4): its velocity has no component
  /// across its horizontal heading (σ sigma_cross_mps) and none vertical (σ sigma_up_mps) — the cross and up rows of
  /// the step-velocity model (step_velocity_rows) at the current velocity. True when the update was applied.
  static bool hand_nhc_update(ErrorStateFilter& f, double sigma_cross_mps, double sigma_up_mps);

 private:
  // ZARU rows: the measured rate (corrected by the current bias estimate) should equal the Earth rate in b; residual
  // into `r`, Jacobian returned (3 x n).
  Rows3 zaru_rows(const ErrorStateFilter& f, const ins::ImuIncrement& inc, Eigen::Vector3d& r) const;
  double zaru_variance(const ins::ImuIncrement& inc) const;
  // ZARU innovation gate (docs/fusion.md §5.3): d² = rᵀ S⁻¹ r, S = H P Hᵀ + R, against χ²(3) at zaru_gate_probability.
  bool zaru_passes_gate(const ErrorStateFilter& f, const Rows3& H, const Eigen::Vector3d& r, double variance) const;

  const EngineOptions& o_;
  const double zaru_gate_threshold_;  // chi2(3) quantile at o_.zaru_gate_probability; 0 = no gate
};

}  // namespace pednav::fusion
