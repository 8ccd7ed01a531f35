// SPDX-License-Identifier: BSD-2-Clause
#include "fusion/step_velocity.hpp"

#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"

namespace pednav::fusion {

double inverted_pendulum_step_length_m(double leg_length_m, double rise_m) {
  if (!(rise_m > 0.0)) return 0.0;
  if (rise_m >= leg_length_m) return 2.0 * leg_length_m;
  return 2.0 * std::sqrt(2.0 * leg_length_m * rise_m - rise_m * rise_m);  // seed 000
}

std::optional<StepMeasurement> StepTracker::push(const ins::NavState& nav, double dt_s, bool stance) {
  const double t_s = nav.t.seconds();
  const Geodetic llh = geodetic_from_ecef(nav.p_eb_e);
  const double v_up = -(R_e_n(llh.lat, llh.lon).transpose() * nav.v_eb_e).z();
  std::optional<StepMeasurement> out;
  const bool onset = stance && !prev_stance_;
  prev_stance_ = stance;
  if (onset) {
    if (started_) {
      const double T = t_s - t0_s_;
      if (T >= o_.min_step_s && T <= o_.max_step_s && samples_.size() >= 2) {
        // h: the largest rise over the first half step, ∫(v_up − v_up(t0)) dt (trapezoidal; seed 000's double
        // integral of the vertical acceleration with zero initial vertical velocity).
        double rise = 0.0, h = 0.0;
        const double v0 = samples_.front().v_up_mps;
        for (size_t i = 1; i < samples_.size() && samples_[i].t_s <= t0_s_ + 0.5 * T + 1e-9; ++i) {
          h += 0.5 * (samples_[i].v_up_mps + samples_[i - 1].v_up_mps - 2.0 * v0) * (samples_[i].t_s - samples_[i - 1].t_s);
          rise = std::max(rise, h);
        }
        if (rise >= o_.min_rise_m) {
          StepMeasurement m;
          m.duration_s = T;
          m.rise_m = rise;
          m.step_length_m = inverted_pendulum_step_length_m(o_.leg_length_m, rise);
          m.model_speed_mps = m.step_length_m / T;
          m.mean_v_e = sum_v_dt_ / T;
          out = m;
        }
      }
    }
    started_ = true;
    t0_s_ = t_s;
    sum_v_dt_.setZero();
    samples_.clear();
    samples_.push_back({t_s, v_up});
    return out;
  }
  if (started_) {
    sum_v_dt_ += nav.v_eb_e * dt_s;
    samples_.push_back({t_s, v_up});
  }
  return out;
}

namespace {

// Horizontal unit vectors of the heading frame: forward (body x projected) and left/right (down × forward).
struct HeadingFrame {
  Eigen::Vector3d a;      // unnormalized projection P_h x_b [-]
  Eigen::Vector3d u_f, u_l, down;
  Eigen::Matrix3d P_h;    // projector on the horizontal
};

HeadingFrame heading_frame(const Eigen::Matrix3d& R_e_b, const Eigen::Vector3d& p_e) {
  HeadingFrame h;
  const Geodetic llh = geodetic_from_ecef(p_e);
  h.down = R_e_n(llh.lat, llh.lon).col(2);
  h.P_h = Eigen::Matrix3d::Identity() - h.down * h.down.transpose();
  h.a = h.P_h * R_e_b.col(0);
  h.u_f = h.a.normalized();
  h.u_l = h.down.cross(h.u_f);
  return h;
}

}  // namespace

Eigen::Vector3d step_velocity_prediction(const Eigen::Vector3d& mean_v_e, const Eigen::Matrix3d& R_e_b,
                                         const Eigen::Vector3d& p_e) {
  const HeadingFrame h = heading_frame(R_e_b, p_e);
  return {h.u_f.dot(mean_v_e), h.u_l.dot(mean_v_e), -h.down.dot(mean_v_e)};
}

StepVelocityRows step_velocity_rows(const ins::NavState& nav, const StepMeasurement& m,
                                    const StepVelocityOptions& o) {
  StepVelocityRows rows;
  const Eigen::Matrix3d R = nav.R_e_b();
  const HeadingFrame h = heading_frame(R, nav.p_eb_e);
  // r = z − h(x̂): z = (ΔL/T, 0, 0) (seed 000 eqs. 2-3; cross-track and vertical: no sideways or net vertical motion).
  rows.residual = Eigen::Vector3d(m.model_speed_mps, 0.0, 0.0) - step_velocity_prediction(m.mean_v_e, R, nav.p_eb_e);
  // ∂h/∂δv: the average velocity error is the current δv (seed 000).
  rows.J_dv_phi.block<1, 3>(0, 0) = h.u_f.transpose();
  rows.J_dv_phi.block<1, 3>(1, 0) = h.u_l.transpose();
  rows.J_dv_phi.block<1, 3>(2, 0) = -h.down.transpose();  // the vertical does not depend on φ
  // ∂h/∂φ: x_true = exp([φ×]) x̂ ≈ x̂ − [x̂×] φ; u_f = a/|a|, a = P_h x; ∂u_f/∂a = (I − u_f u_fᵀ)/|a|; u_l = [d×] u_f.
  const Eigen::Matrix3d du_f = (Eigen::Matrix3d::Identity() - h.u_f * h.u_f.transpose()) / h.a.norm() * h.P_h *
                               (-skew(Eigen::Vector3d(R.col(0))));
  rows.J_dv_phi.block<1, 3>(0, 3) = m.mean_v_e.transpose() * du_f;
  rows.J_dv_phi.block<1, 3>(1, 3) = m.mean_v_e.transpose() * skew(h.down) * du_f;
  rows.cov_meas = Eigen::Vector3d(o.sigma_along_mps * o.sigma_along_mps, o.sigma_cross_mps * o.sigma_cross_mps,
                                  o.sigma_vertical_mps * o.sigma_vertical_mps)
                      .asDiagonal();
  return rows;
}

}  // namespace pednav::fusion
