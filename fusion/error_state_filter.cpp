// SPDX-License-Identifier: BSD-2-Clause
// The engine's filter (fusion/error_state_filter.hpp): propagation, feedback, restarts, health, compensation totals.
#include "fusion/error_state_filter.hpp"

#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/health.hpp"
#include "ins/mechanization.hpp"

namespace pednav::fusion {
namespace {

using Eigen::Vector3d;

// Plausibility bounds of the nominal state (health check): 6250..6500 km from the centre covers every point from
// below the Dead Sea to 120 km altitude at any latitude; 100 m/s is far above any foot speed.
constexpr double kMinRadius_m = 6.25e6;
constexpr double kMaxRadius_m = 6.5e6;
constexpr double kMaxSpeed_mps = 100.0;

}  // namespace

// The IMU spec as the filter models it. With bias_random_walk the Gauss-Markov bias part (σ, τ) becomes a random
// walk of the same PSD 2σ²/τ (docs/error_state.md eq. 3.4-3.5 with τ <= 0): the state's turn-on variance then stays
// until a measurement reduces it, instead of decaying with τ (which the one-state GM model does although the
// turn-on bias is a constant: at τ = 300 s the Crista's 30 mg prior is "forgotten" to 20 mg within a 120 s static
// start, unobserved; docs/consistency.md §3.2). initial_covariance still takes max(turn-on, instability).
ins::ImuSpec filter_spec(const EngineOptions& o) {
  ins::ImuSpec s = o.spec;
  if (!o.bias_random_walk) return s;
  auto to_walk = [](double& instability, double& tau_s, double& rw, double& initial) {
    if (!(instability > 0.0 && tau_s > 0.0)) return;
    initial = std::max(initial, instability);
    rw = std::sqrt(rw * rw + 2.0 * instability * instability / tau_s);
    instability = 0.0;
    tau_s = 0.0;
  };
  to_walk(s.gyro_bias_instability, s.gyro_bias_tau_s, s.gyro_bias_rw, s.gyro_bias_initial);
  to_walk(s.accel_bias_instability, s.accel_bias_tau_s, s.accel_bias_rw, s.accel_bias_initial);
  return s;
}

ErrorStateFilter::ErrorStateFilter(const EngineOptions& o, int n_clocks) : o_(o), spec_(filter_spec(o)) {
  if (o.estimate_scale_factors) {  // the INS error model owns these blocks (docs/error_state.md)
    for (const char* name : {ins::kScaleGyroBlock, ins::kScaleAccBlock}) {
      if (!o.estimate_gyro_scale_factors && std::string(name) == ins::kScaleGyroBlock) continue;
      if (auto b = layout_.add(name, 3); !b) {
        problem_ = b.error().message;
        return;
      }
    }
  }
  if (o.mode == Mode::kTightlyCoupled) {
    for (int i = 0; i < n_clocks; ++i) {
      auto b = layout_.add("clock_" + std::to_string(i), 1);
      if (!b) {
        problem_ = b.error().message;
        return;
      }
      clock_blocks_.push_back(*b);
    }
    auto d = layout_.add("drift", 1);
    if (!d) {
      problem_ = d.error().message;
      return;
    }
    drift_block_ = *d;
    if (o.multipath_sigma_m > 0.0 && o.multipath_slots > 0) {
      auto b = layout_.add("multipath", o.multipath_slots);
      if (!b) {
        problem_ = b.error().message;
        return;
      }
      mp_block_ = *b;
      mp_value_.assign(o.multipath_slots, 0.0);
      mp_sat_.assign(o.multipath_slots, gnss::SatId{});
      mp_last_ns_.assign(o.multipath_slots, kNeverNs);
    }
    if (o.carrier && o.ambiguity_slots > 0) {
      auto b = layout_.add("ambiguity", o.ambiguity_slots);
      if (!b) {
        problem_ = b.error().message;
        return;
      }
      amb_block_ = *b;
      amb_value_.assign(o.ambiguity_slots, 0.0);
    }
    if (o.antenna_state) {
      auto b = layout_.add("antenna", 9);
      if (!b) {
        problem_ = b.error().message;
        return;
      }
      ant_block_ = *b;
    }
  }
  // The g-sensitive gyro error (docs/error_state.md §5) when the spec gives its σ; after the GNSS blocks, so that
  // the errors-in-variables footprints of tc (kept on the leading INS block) do not carry it.
  if (spec_.gyro_g_sensitivity > 0.0) {
    auto b = layout_.add(ins::kGSensitivityBlock, 9);
    if (!b) {
      problem_ = b.error().message;
      return;
    }
    g_sens_offset_ = b->offset;
    consider_ = ConsiderStates{b->offset, 9};
  }
  if (o.scale_bias_compensation) {  // docs/consistency.md §3.6
    for (const char* name : {ins::kScaleGyroBlock, ins::kScaleAccBlock}) {
      const auto b = layout_.find(name);
      if (!b) continue;
      const bool gyro = std::string(name) == ins::kScaleGyroBlock;
      for (int axis = 0; axis < 3; ++axis) {
        eiv_.push_back(EivTerm{b->offset + axis, gyro ? ins::kAtt.offset : ins::kVel.offset, axis, gyro});
      }
    }
  }
  clock_m_.assign(n_clocks, 0.0);
  for (const ins::Block& b : {ins::kPos, ins::kVel, ins::kAtt}) {
    for (int i = 0; i < b.dim; ++i) dense_rows_[n_dense_rows_++] = b.offset + i;
  }
  n_dense_rows_ins_ = n_dense_rows_;
  for (const auto& b : clock_blocks_) dense_rows_[n_dense_rows_++] = b.offset;
  for (int i = 0; i < (ant_block_.dim > 0 ? 3 : 0); ++i) dense_rows_[n_dense_rows_++] = ant_block_.offset + i;
}

void ErrorStateFilter::init_antenna(const Vector3d& p_e, const Vector3d& v_e, const Eigen::Matrix3d& cov_p_e,
                                    const Eigen::Matrix3d& cov_v_e, const Eigen::Matrix3d& cov_b_h) {
  if (ant_block_.dim == 0) return;
  const int a = ant_block_.offset;
  for (int i = 0; i < 9; ++i) restart_variable(a + i, 1.0);  // independent of everything (also in the smoother)
  auto set = [&](ErrorMatrix& P) {
    P.block<3, 3>(a, a) = cov_p_e;
    P.block<3, 3>(a + 3, a + 3) = cov_v_e;
    P.block<3, 3>(a + 6, a + 6) = cov_b_h;
  };
  ant_b_h_.setZero();
  set(P_);
  if (shadow_) set(Po_);
  ant_p_e_ = p_e;
  ant_v_e_ = v_e;
  const Geodetic llh = geodetic_from_ecef(p_e);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  const double qh = o_.antenna_accel_sigma_horizontal_mps2 * o_.antenna_accel_sigma_horizontal_mps2;
  const double qv = o_.antenna_accel_sigma_vertical_mps2 * o_.antenna_accel_sigma_vertical_mps2;
  ant_q_e_ = Ren * Vector3d(qh, qh, qv).asDiagonal() * Ren.transpose();
}

void ErrorStateFilter::init(const ins::NavState& nav, const ins::ImuErrors& imu, double sigma_yaw_rad) {
  x_.nav = nav;
  x_.imu = imu;
  const double st = o_.initial_sigma_tilt_rad;
  P_ = ins::initial_covariance(layout_, spec_, o_.initial_sigma_pos_m, o_.initial_sigma_vel_mps,
                               Vector3d(st, st, st));
  // The attitude block is resolved in e: build it from NED sigmas (tilt, tilt, yaw).
  const Geodetic llh = geodetic_from_ecef(nav.p_eb_e);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  const Eigen::Matrix3d att_n = Vector3d(st * st, st * st, sigma_yaw_rad * sigma_yaw_rad).asDiagonal();
  P_.block<3, 3>(ins::kAtt.offset, ins::kAtt.offset) = Ren * att_n * Ren.transpose();
  for (const auto& b : clock_blocks_) P_(b.offset, b.offset) = 1e12;  // unknown until the first GNSS epoch
  if (o_.mode == Mode::kTightlyCoupled) P_(drift_block_.offset, drift_block_.offset) = 1e6;
  for (int i = 0; i < amb_block_.dim; ++i) {  // no satellite yet (also at a re-initialization)
    P_(amb_block_.offset + i, amb_block_.offset + i) = 1.0;
    amb_value_[i] = 0.0;
  }
  if (ant_block_.dim > 0) {  // until init_antenna: at the IMU, 100 m (also at a re-initialization)
    ant_p_e_ = nav.p_eb_e;
    ant_v_e_.setZero();
    ant_b_h_.setZero();
    for (int i = 0; i < 9; ++i) P_(ant_block_.offset + i, ant_block_.offset + i) = 1e4;
  }
  for (int i = 0; i < mp_block_.dim; ++i) {  // unit-variance GM, no satellite yet (also at a re-initialization)
    P_(mp_block_.offset + i, mp_block_.offset + i) = 1.0;
    mp_value_[i] = 0.0;
    mp_last_ns_[i] = kNeverNs;
  }
  // The footprints are kept on the INS states only (core and scale: the leading block of the layout), not on
  // the clocks and multipath states the GNSS updates also correlate them with (docs/consistency.md §3.7: the
  // subtracted totals change by < 2 % on the large ones, 5 % on the smallest, at about half the cost).
  eiv_dim_ = clock_blocks_.empty() ? layout_.dim() : clock_blocks_.front().offset;
  eiv_stack_.reset(eiv_dim_, static_cast<int>(eiv_.size()));  // no noise footprint yet (also at a re-init)
  interval_.restart(P_);  // sized; the smoother's bookkeeping starts at the first output epoch (smoother_restart)
  // With consider states the smoother runs on the Kalman-gain filter of the same linearization (docs/fusion.md
  // §12.6): its covariance starts as the filter's, its conditional mean of the error at zero. It has its own
  // errors-in-variables footprints, over the whole state: its gain also corrects the consider states, and the INS
  // block alone is not stable under that gain (the footprint grew to 1e10 on the 1 °/s/g test walk).
  shadow_ = consider_.count > 0 && o_.smoother_enabled;
  eivo_.clear();
  if (shadow_) {
    Po_ = P_;
    eta_.setZero(P_.rows());
    eivo_ = eiv_;
    eivo_stack_.reset(layout_.dim(), static_cast<int>(eivo_.size()));
  }
}

void ErrorStateFilter::set_block_sigma(const ins::Block& b, double sigma) {
  auto reset = [&](ErrorMatrix& P) {
    P.middleRows<3>(b.offset).setZero();
    P.middleCols<3>(b.offset).setZero();
    P.block<3, 3>(b.offset, b.offset) = Eigen::Matrix3d::Identity() * sigma * sigma;
  };
  reset(P_);
  if (shadow_) {
    reset(Po_);
    eta_.segment<3>(b.offset).setZero();
  }
}

void ErrorStateFilter::predict(const ins::ImuIncrement& inc) {
  const ins::NavState after = ins::mechanize(x_.nav, inc);
  ins::DiscreteErrorModel& m = model_;
  ins::interval_error_model(layout_, spec_, x_.nav, after, inc, m);
  if (saturation_noise_) {  // reconstructed clipped samples in this interval (docs/ins.md eq. 9.4)
    const Eigen::Matrix3d R = x_.nav.q_e_b.toRotationMatrix();
    m.Qd.block<3, 3>(ins::kAtt.offset, ins::kAtt.offset) += R * sat_att_var_b_.asDiagonal() * R.transpose();
    m.Qd.block<3, 3>(ins::kVel.offset, ins::kVel.offset) += R * sat_vel_var_b_.asDiagonal() * R.transpose();
    sat_att_var_b_.setZero();
    sat_vel_var_b_.setZero();
    saturation_noise_ = false;
  }
  const double dt = inc.dt_s;
  if (o_.mode == Mode::kTightlyCoupled) {
    const int d = drift_block_.offset;
    const double qc = o_.clock_psd_m2_per_s, qd = o_.drift_psd_m2_per_s3;
    m.Qd(d, d) += qd * dt;
    for (size_t i = 0; i < clock_blocks_.size(); ++i) {
      const int c = clock_blocks_[i].offset;
      m.Phi(c, d) = dt;  // clock += drift dt
      m.Qd(c, c) += qc * dt + qd * dt * dt * dt / 3.0;
      m.Qd(c, d) += qd * dt * dt / 2.0;
      m.Qd(d, c) += qd * dt * dt / 2.0;
      clock_m_[i] += drift_mps_ * dt;
    }
  }
  // Code multipath (docs/consistency.md eq. M.1): u(t + dt) = e u(t) + w, e = exp(−dt/τ), var w = 1 − e².
  if (mp_block_.dim > 0) {
    const double e = std::exp(-dt / o_.multipath_tau_s);
    for (int i = 0; i < mp_block_.dim; ++i) {
      const int k = mp_block_.offset + i;
      m.Phi(k, k) = e;
      m.Qd(k, k) += 1.0 - e * e;
      mp_value_[i] *= e;
    }
  }
  // Antenna (docs/carrier.md eq. 10.1): p_a += v_a dt, white acceleration of PSD Q_a.
  if (ant_block_.dim > 0) {
    const int a = ant_block_.offset, v = a + 3;
    for (int i = 0; i < 3; ++i) m.Phi(a + i, v + i) = dt;
    m.Qd.block<3, 3>(a, a) += ant_q_e_ * (dt * dt * dt / 3.0);
    m.Qd.block<3, 3>(a, v) += ant_q_e_ * (dt * dt / 2.0);
    m.Qd.block<3, 3>(v, a) += ant_q_e_ * (dt * dt / 2.0);
    m.Qd.block<3, 3>(v, v) += ant_q_e_ * dt;
    ant_p_e_ += ant_v_e_ * dt;
  }
  Phi_rows_.assign(m.Phi, dense_rows_, n_dense_rows_);
  // Smoother: the cross-covariance of the error at the last output epoch with the current error, Γ ← Γ Φᵀ
  // (docs/fusion.md eq. 12.15).
  if (recording_) interval_.predict(Phi_rows_);
  if (!eiv_.empty()) eiv_predict(inc.dt_s, x_.nav, after, eiv_, eiv_stack_, P_);
  if (shadow_ && !eivo_.empty()) eiv_predict(inc.dt_s, x_.nav, after, eivo_, eivo_stack_, Po_);
  if (shadow_) {  // the Kalman-gain filter of the smoother (docs/fusion.md eq. 12.22): η ← Φ η, P_o ← Φ P_o Φᵀ + Q_d
    Phi_rows_.times_in_place(eta_, eta_tmp_);
    covariance_predict(Po_, Phi_rows_, m.Qd, tmp_);
  }
  covariance_predict(P_, Phi_rows_, m.Qd, tmp_);
  x_.nav = after;
}

void ErrorStateFilter::apply(const ErrorVector& dx) {
  x_ = ins::boxplus(x_, dx, layout_);
  for (size_t i = 0; i < clock_blocks_.size(); ++i) clock_m_[i] += dx(clock_blocks_[i].offset);
  if (o_.mode == Mode::kTightlyCoupled) drift_mps_ += dx(drift_block_.offset);
  for (int i = 0; i < mp_block_.dim; ++i) mp_value_[i] += dx(mp_block_.offset + i);
  for (int i = 0; i < amb_block_.dim; ++i) amb_value_[i] += dx(amb_block_.offset + i);
  if (ant_block_.dim > 0) {
    ant_p_e_ += dx.segment<3>(ant_block_.offset);
    ant_v_e_ += dx.segment<3>(ant_block_.offset + 3);
    ant_b_h_ += dx.segment<3>(ant_block_.offset + 6);
  }
}

int ErrorStateFilter::multipath_slot(const gnss::SatId& sat, int64_t t_ns, bool& reset) {
  reset = false;
  const int64_t gap_ns = static_cast<int64_t>(o_.multipath_reset_gap_s * 1e9);
  int lru = -1;
  for (int i = 0; i < mp_block_.dim; ++i) {
    if (mp_last_ns_[i] != kNeverNs && mp_sat_[i] == sat) {
      if (mp_last_ns_[i] == t_ns || t_ns - mp_last_ns_[i] <= gap_ns) {
        mp_last_ns_[i] = t_ns;
        return i;
      }
      lru = i;  // the same satellite after a long gap: restart its own slot
      break;
    }
    if (mp_last_ns_[i] < t_ns && (lru < 0 || mp_last_ns_[i] < mp_last_ns_[lru])) lru = i;
  }
  if (lru < 0) return -1;
  const int k = mp_block_.offset + lru;
  mp_sat_[lru] = sat;
  mp_last_ns_[lru] = t_ns;
  mp_value_[lru] = 0.0;
  restart_variable(k, 1.0);
  reset = true;
  return lru;
}

void ErrorStateFilter::reexpress_velocity_attitude(const Eigen::Matrix3d& A) {
  reexpress_velocity_attitude(A, P_);
  if (shadow_) {  // the smoother's Kalman-gain filter: P_o ← J P_o Jᵀ, η ← J η
    reexpress_velocity_attitude(A, Po_);
    const Vector3d eta_att = eta_.segment<3>(ins::kAtt.offset);
    eta_.segment<3>(ins::kVel.offset) += A * eta_att;
  }
  // The smoother's cross-covariance follows the coordinate change: Γ ← Γ Jᵀ (docs/fusion.md eq. 12.18).
  if (recording_) interval_.reexpress(ins::kVel.offset, ins::kAtt.offset, A);
}

void ErrorStateFilter::reexpress_velocity_attitude(const Eigen::Matrix3d& A, ErrorMatrix& P_) {
  // J P J^T = P + E_v A P_φ· + P_·φ A^T E_v^T + E_v A P_φφ A^T E_v^T
  const int v = ins::kVel.offset, a = ins::kAtt.offset;
  Rows3 APa;
  APa.noalias() = A * P_.middleRows<3>(a);  // A P_φ· (3 x n), from the P before the update
  const Eigen::Matrix3d APaaAt = A * P_.block<3, 3>(a, a) * A.transpose();
  P_.middleRows<3>(v) += APa;
  P_.middleCols<3>(v) += APa.transpose();
  P_.block<3, 3>(v, v) += APaaAt;
  // The row and column updates are mirror images of each other, so only the (v, v) block can lose symmetry (by
  // the rounding of A P_φφ Aᵀ): symmetrize that block (the whole matrix would cost n² per ZUPT).
  const Eigen::Matrix3d Pvv = P_.block<3, 3>(v, v);
  P_.block<3, 3>(v, v) = 0.5 * (Pvv + Pvv.transpose());
}

void ErrorStateFilter::restart_variable(int i, double variance) {
  auto reset = [&](ErrorMatrix& P) {
    P.row(i).setZero();
    P.col(i).setZero();
    P(i, i) = variance;
  };
  reset(P_);
  if (shadow_) {
    reset(Po_);
    eta_(i) = 0.0;
  }
  if (recording_) interval_.restart_state(i);
}

void ErrorStateFilter::reset_clock(int slot, double value_m, double sigma_m) {
  const int c = clock_blocks_[slot].offset;
  clock_m_[slot] = value_m;
  restart_variable(c, sigma_m * sigma_m);
}

void ErrorStateFilter::reset_drift(double value_mps, double sigma_mps) {
  const int d = drift_block_.offset;
  drift_mps_ = value_mps;
  restart_variable(d, sigma_mps * sigma_mps);
}

void ErrorStateFilter::smoother_restart() {
  if (shadow_) {
    interval_.restart(Po_, eta_);  // eq. 12.21
  } else {
    interval_.restart(P_);
  }
  recording_ = true;
}

void ErrorStateFilter::smoother_close(RtsSegment& out) const {
  if (shadow_) {
    interval_.close(Po_, eta_, out);
  } else {
    interval_.close(P_, out);
  }
}

bool ErrorStateFilter::healthy(std::string& why, bool check_covariance) const {
  // The sum of P is finite exactly when every entry is (a NaN or ±inf anywhere makes it non-finite), except when
  // finite entries near 1e308 overflow: then the entry-wise test decides. One vectorized reduction per step.
  const bool p_finite = std::isfinite(P_.sum()) || P_.allFinite();
  if (!p_finite || !x_.nav.p_eb_e.allFinite() || !x_.nav.v_eb_e.allFinite()) {
    why = "non-finite state or covariance";
    return false;
  }
  for (int i = 0; i < P_.rows(); ++i) {
    if (P_(i, i) < 0.0) {  // zero is legitimate for a state without uncertainty (e.g. a bias with no noise)
      why = "negative variance of state " + std::to_string(i);
      return false;
    }
  }
  if (const char* defect = check_covariance ? covariance_defect(P_) : nullptr) {
    why = defect;
    return false;
  }
  // A walking person stays near the Earth's surface and below vehicle speeds: anything else is divergence,
  // even while the covariance still looks healthy.
  const double r_m = x_.nav.p_eb_e.norm();
  if (r_m < kMinRadius_m || r_m > kMaxRadius_m) {
    why = "position " + std::to_string(r_m * 1e-3) + " km from the Earth's centre (outside 6250..6500 km)";
    return false;
  }
  if (x_.nav.v_eb_e.norm() > kMaxSpeed_mps) {
    why = "speed " + std::to_string(x_.nav.v_eb_e.norm()) + " m/s (a walking person stays below 100 m/s)";
    return false;
  }
  return true;
}

ImuEstimate ErrorStateFilter::imu_estimate() const {
  ImuEstimate e;
  e.value = x_.imu;
  auto sd = [&](int offset) {
    return Vector3d(std::sqrt(P_(offset, offset)), std::sqrt(P_(offset + 1, offset + 1)),
                    std::sqrt(P_(offset + 2, offset + 2)));
  };
  e.sd.b_g = sd(ins::kBiasGyro.offset);
  e.sd.b_a = sd(ins::kBiasAcc.offset);
  if (const auto b = layout_.find(ins::kScaleGyroBlock)) {
    e.gyro_scale = true;
    e.sd.s_g = sd(b->offset);
    for (int i = 0; i < 3; ++i) e.gyro_scale_compensation(i) = eiv_correction(b->offset + i);
  }
  if (const auto b = layout_.find(ins::kScaleAccBlock)) {
    e.accel_scale = true;
    e.sd.s_a = sd(b->offset);
    for (int i = 0; i < 3; ++i) e.accel_scale_compensation(i) = eiv_correction(b->offset + i);
  }
  if (g_sens_offset_ >= 0) {
    e.g_sensitivity = true;
    for (int k = 0; k < 9; ++k) e.sd.G_g(k % 3, k / 3) = std::sqrt(P_(g_sens_offset_ + k, g_sens_offset_ + k));
  }
  return e;
}

double ErrorStateFilter::eiv_correction(int state) const {
  for (const auto& t : eiv_) {
    if (t.state == state) return t.total;
  }
  return 0.0;
}

void ErrorStateFilter::eiv_predict(double dt, const ins::NavState& before, const ins::NavState& after, std::vector<EivTerm>& terms,
                 EivStack& stack, const ErrorMatrix& P) {
  const int n = terms.empty() ? 0 : stack.n;
  if (n != layout_.dim()) eiv_Phi_.assign(model_.Phi.topLeftCorner(n, n), dense_rows_, n_dense_rows_ins_);
  const auto& Phi = n != layout_.dim() ? eiv_Phi_ : Phi_rows_;
  const Eigen::Matrix3d R = before.q_e_b.slerp(0.5, after.q_e_b).toRotationMatrix();
  // Φ M Φᵀ for every footprint (no process noise of its own).
  Phi.propagate_stacked(stack.s.data(), stack.count, stack.u.data(), stack.ut.data(), stack.zt.data());
  // The noise ν_u of every scale term u's regressor enters P's column of scale state t through P_tu (its own column
  // of Φ times P_{s_u s_t}), and the error through g_u: M_t gains Σ_u P_tu σ_u² Δt g_u g_uᵀ (docs/consistency.md
  // eq. E.5).
  for (size_t ti = 0; ti < terms.size(); ++ti) {
    const EivTerm& t = terms[ti];
    auto M = stack.block(static_cast<int>(ti));
    for (const auto& u : terms) {
      const double psd = u.gyro ? spec_.gyro_arw * spec_.gyro_arw : spec_.accel_vrw * spec_.accel_vrw;
      const Vector3d g = R.col(u.axis);
      M.block<3, 3>(u.block_offset, u.block_offset).noalias() += (P(t.state, u.state) * psd * dt) * (g * g.transpose());
    }
  }
}

void ErrorStateFilter::eiv_subtract(std::vector<EivTerm>& terms, const double* bias, ErrorVector& dx, bool shift_interval,
                  const ErrorMatrix& P) {
  int states[kMaxEivTerms];
  double deviation[kMaxEivTerms];
  for (size_t j = 0; j < terms.size(); ++j) {
    dx(terms[j].state) -= bias[j];
    terms[j].total += bias[j];
    states[j] = terms[j].state;
    deviation[j] = -bias[j];
  }
  if (!shift_interval) return;
  if (o_.smoother_eiv_regression) {
    interval_.shift_mean_regressed(states, deviation, static_cast<int>(terms.size()), P);
  } else {
    for (size_t j = 0; j < terms.size(); ++j) interval_.shift_mean(states[j], deviation[j]);
  }
}
}  // namespace pednav::fusion
