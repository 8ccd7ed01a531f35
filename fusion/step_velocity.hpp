// SPDX-License-Identifier: BSD-2-Clause
// Step-averaged velocity aiding from a biomechanical step-length model (seed 000, issue 9).
//
// Seed 000: the pedestrian moves like an inverted pendulum of length l; the rise h of the centre of mass over the
// first half of a step (double integral of the vertical acceleration) gives the step length ΔL = 2√(2lh − h²),
// and ΔL / T_k the step's average speed, along the walking direction. The INS's own average velocity over the
// step is compared with it: S = V̄_INS − V̄_model = δV + n (seed 000 eq. 3), with δV the INS velocity error, taken
// constant over the step (seed 000: "the errors δV during the step are almost constant").
//
// Here a "step" is the interval between two stance onsets of the IMU foot (the ZUPT detector segments the walk
// whether or not ZUPT updates are applied), h is the IMU's own rise over the first half of that interval, and l is
// a per-person parameter (for a foot IMU it is a calibrated model constant, not the anatomical leg length:
// docs/consistency.md §5). The measurement is 3-D, resolved in the heading frame of the IMU (forward axis projected
// on the horizontal): along-track ΔL/T = u_fᵀ V̄ + n_f, cross-track 0 = u_lᵀ V̄ + n_l (the average velocity of a
// step has no sideways component) and vertical 0 = u_upᵀ V̄ + n_u (level walking; seed 000 treats the horizontal
// channels only, but without ZUPTs the INS vertical channel is unstable and needs this). The Jacobian w.r.t. the
// current velocity and attitude errors is in StepVelocityRows; no file I/O, no logging.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "ins/nav_state.hpp"

namespace pednav::fusion {

/// Options of the step-velocity measurement (config key step_velocity).
struct StepVelocityOptions {
  bool enabled = false;
  double leg_length_m = 0.55;        ///< l of ΔL = 2√(2lh − h²) [m]
  double sigma_along_mps = 0.05;     ///< n: along-track speed noise [m/s] (seed 000 σ_n)
  double sigma_cross_mps = 0.05;     ///< cross-track noise [m/s]
  double sigma_vertical_mps = 0.05;  ///< vertical (level walking) noise [m/s]
  double min_step_s = 0.4;           ///< shorter intervals between stance onsets are not steps [s]
  double max_step_s = 3.0;           ///< longer ones (standing, turning in place) are not used [s]
  double min_rise_m = 0.01;          ///< below this rise the person is not walking: no update [m]
};

/// Inverted-pendulum step length ΔL = 2√(2 l h − h²) [m] for pendulum length l [m] and rise h [m] (seed 000);
/// 0 for h <= 0, and 2l for h >= l (the pendulum cannot rise further).
double inverted_pendulum_step_length_m(double leg_length_m, double rise_m);

/// One completed step: the INS average velocity over it and the model's average speed.
struct StepMeasurement {
  double duration_s = 0.0;                            ///< T_k [s]
  double rise_m = 0.0;                                ///< h [m]
  double step_length_m = 0.0;                         ///< ΔL [m]
  double model_speed_mps = 0.0;                       ///< ΔL / T_k [m/s]
  Eigen::Vector3d mean_v_e = Eigen::Vector3d::Zero(); ///< INS average velocity over the step, ECEF [m/s]
};

/// Segments the mechanization epochs into steps (stance onset to stance onset) and accumulates, per step, the INS
/// average velocity and the rise over its first half (double integral of the vertical acceleration with zero
/// initial vertical velocity, computed from the INS vertical velocity minus its value at the step start).
class StepTracker {
 public:
  explicit StepTracker(StepVelocityOptions options) : o_(options) {}
  /// Feed one mechanization epoch: nominal state at its end (GPST t inside), its duration dt_s [s], and whether
  /// the detector flags stance there. Returns a measurement when this epoch completes a valid step.
  std::optional<StepMeasurement> push(const ins::NavState& nav, double dt_s, bool stance);

 private:
  struct Sample {
    double t_s, v_up_mps;
  };
  StepVelocityOptions o_;
  bool started_ = false, prev_stance_ = false;
  double t0_s_ = 0.0;
  Eigen::Vector3d sum_v_dt_ = Eigen::Vector3d::Zero();
  std::vector<Sample> samples_;
};

/// The measurement model for the current nominal state `nav` (ECEF, the step's end) and a step measurement:
/// residual r = measured − predicted (3: along, cross, up) [m/s], Jacobian w.r.t. the velocity error δv (3) and the
/// attitude error φ (3) of docs/error_state.md (v_true = v̂ + δv, R_true = exp([φ×]) R̂), treating the step's average
/// velocity error as the current δv (seed 000).
struct StepVelocityRows {
  Eigen::Vector3d residual = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 3, 6> J_dv_phi = Eigen::Matrix<double, 3, 6>::Zero();  ///< [∂/∂δv, ∂/∂φ]
  Eigen::Matrix3d cov_meas = Eigen::Matrix3d::Zero();
};

/// Predicted measurement h(x) = [u_fᵀ v̄, u_lᵀ v̄, u_upᵀ v̄] (along, cross, up) for the average velocity v̄_e [m/s,
/// ECEF] and the attitude R_e_b at position p_e [m, ECEF]: u_f = the body x axis projected on the local horizontal
/// and normalized, u_l = down × u_f, u_up = −down.
Eigen::Vector3d step_velocity_prediction(const Eigen::Vector3d& mean_v_e, const Eigen::Matrix3d& R_e_b,
                                         const Eigen::Vector3d& p_e);

/// Rows of the update (residual, Jacobian, noise) for nominal `nav` and a step measurement.
StepVelocityRows step_velocity_rows(const ins::NavState& nav, const StepMeasurement& m,
                                    const StepVelocityOptions& options);

}  // namespace pednav::fusion
