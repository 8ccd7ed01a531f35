// SPDX-License-Identifier: BSD-2-Clause
// The engine's filter: the nominal INS state with the differential receiver clocks, and the covariance of its error
// state. Propagation (Φ, Q_d at the mechanization rate, clocks and multipath Gauss-Markov slots), the Joseph-form
// update with closed-loop feedback, restarts of single states (clock jumps, multipath slots), the health check, the
// errors-in-variables compensation of the scale-factor updates (docs/consistency.md §3.6), and the smoother's
// bookkeeping of every step (docs/fusion.md §12). Which measurement rows exist is not its business: fusion/
// gnss_update, fusion/stance_updates build them. Internal to the engine (fusion/engine.hpp is the public API).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/row_transition.hpp"
#include "fusion/engine_types.hpp"
#include "fusion/kalman.hpp"
#include "fusion/rts.hpp"
#include "gnss/types.hpp"
#include "ins/error_state.hpp"
#include "ins/imu.hpp"
#include "ins/nav_state.hpp"

namespace pednav::fusion {

/// Three rows over the error state (fixed capacity: no heap allocation in the update loop).
using Rows3 = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor, 3, ins::kMaxErrorDim>;

/// The IMU spec as the filter models it: with EngineOptions::bias_random_walk the Gauss-Markov bias part becomes a
/// random walk of the same PSD (docs/error_state.md eq. 3.4-3.5).
ins::ImuSpec filter_spec(const EngineOptions& o);

// The filter state: nominal INS state + differential clocks, error covariance. Matrices have a fixed capacity
// (ins::ErrorMatrix): nothing here allocates on the heap per step (docs/performance.md).
class ErrorStateFilter {
 public:
  ErrorStateFilter(const EngineOptions& o, int n_clocks);

  /// Why the filter cannot run (e.g. more states than ins::kMaxErrorDim), empty if it can.
  const std::string& problem() const { return problem_; }

  void init(const ins::NavState& nav, const ins::ImuErrors& imu, double sigma_yaw_rad);

  // Replace the variance of a 3-state block (position [m], velocity [m/s]) by sigma² per axis, uncorrelated
  // (re-initialization).
  void set_block_sigma(const ins::Block& b, double sigma);

  // Mechanize one (already bias-corrected) increment and propagate the covariance.
  void predict(const ins::ImuIncrement& inc);

  /// The error a reconstructed saturated run leaves (variance [rad²] of a gyro run's angle or [m²/s²] of an
  /// accelerometer run's velocity, about/along body axis `axis`): process noise of the next prediction.
  void add_saturation_noise(bool gyro, int axis, double variance) {
    (gyro ? sat_att_var_b_ : sat_vel_var_b_)(axis) += variance;
    saturation_noise_ = true;
  }

  // Joseph-form update with residuals r (measured - predicted), Jacobian H and noise covariance R;
  // the correction is fed back into the nominal state (closed loop) and the error state reset to zero.
  template <typename MatH, typename VecR, typename MatR>
  bool update(const VecR& r, const MatH& H, const MatR& R) {
    ErrorVector dx;
    // Smoother: the estimate of the error at the last output epoch, its variance and its cross-covariance with the
    // current error are conditioned on the same measurement, with the filter's S and K (docs/fusion.md eqs.
    // 12.16-12.17).
    // Errors-in-variables compensation (docs/consistency.md eq. E.4): the mean noise part of each scale correction.
    double eiv_bias[kMaxEivTerms];
    const bool ok = joseph_update(P_, H, r, R, dx, [&](const auto& S_ldlt, const auto& K) {
      if (recording_ && !shadow_) interval_.update(H, r, S_ldlt, K);
      eiv_update_all(eiv_, eiv_stack_, H, S_ldlt, K, eiv_bias);
    }, consider_);
    if (!ok) return false;
    if (shadow_) {
      // The smoother's Kalman-gain filter (docs/fusion.md eq. 12.23) conditions its mean η of the error on the same
      // residual, ν = r − H η; the smoother's interval uses its S and gain.
      VecR nu = r;
      nu.noalias() -= H * eta_;
      // Its gain has the same errors-in-variables mean as the filter's (docs/consistency.md eq. E.4), from its own
      // footprints; without the subtraction η's scale part drifts by it at every update.
      ErrorVector dxo;
      double eivo_bias[kMaxEivTerms];
      if (joseph_update(Po_, H, nu, R, dxo, [&](const auto& So_ldlt, const auto& Ko) {
            if (recording_) interval_.update(H, nu, So_ldlt, Ko);
            eiv_update_all(eivo_, eivo_stack_, H, So_ldlt, Ko, eivo_bias);
          })) {
        eiv_subtract(eivo_, eivo_bias, dxo, recording_, Po_);
        eta_ += dxo;
      }
    }
    // The smoother's interval conditions on the forward filter's residual unless the Kalman-gain filter runs (then η
    // carries the subtraction, eq. 12.23).
    eiv_subtract(eiv_, eiv_bias, dx, recording_ && !shadow_, P_);
    apply(dx);
    if (shadow_) eta_ -= dx;  // the nominal moved by dx: the error's conditional mean moves by −dx (eq. 12.23)
    return true;
  }

  void apply(const ErrorVector& dx);

  /// The multipath state of satellite `sat` measured at rover epoch t_ns [GPST ns]: its slot, or (satellite new, or
  /// not measured for longer than multipath_reset_gap_s) a slot restarted as a fresh unit-variance state — the
  /// least recently used slot not yet used at this epoch. `reset` tells whether it was restarted. -1 when every slot
  /// is in use at this epoch (that satellite's code is then treated as white, docs/consistency.md §3).
  int multipath_slot(const gnss::SatId& sat, int64_t t_ns, bool& reset);
  /// First state of the g-sensitivity block (column-major G_g), −1 without it.
  int g_sensitivity_offset() const { return g_sens_offset_; }
  /// State index of multipath slot `slot`; its nominal value u (closed loop: normally 0 after each update, decayed).
  int multipath_index(int slot) const { return mp_block_.offset + slot; }
  double multipath_value(int slot) const { return mp_value_[slot]; }
  bool has_multipath() const { return mp_block_.dim > 0; }
  /// SD carrier-phase ambiguity slots [cycles] (EngineOptions::carrier, docs/carrier.md §8): the first state, the
  /// number of slots, and each slot's nominal value (closed loop: the updates add their correction to it).
  int ambiguity_offset() const { return amb_block_.offset; }
  int ambiguity_slots() const { return amb_block_.dim; }
  double& ambiguity_value(int slot) { return amb_value_[slot]; }
  /// Antenna states (EngineOptions::antenna_state, docs/carrier.md §10): first state of the antenna position error
  /// (its velocity error follows at +3, the arm's error in the foot's heading frame at +6), −1 without; the nominal
  /// antenna position [m] and velocity [m/s], ECEF, and the arm's error [m] (forward, right, down).
  bool has_antenna() const { return ant_block_.dim > 0; }
  int antenna_offset() const { return ant_block_.dim > 0 ? ant_block_.offset : -1; }
  const Eigen::Vector3d& antenna_p_e() const { return ant_p_e_; }
  const Eigen::Vector3d& antenna_v_e() const { return ant_v_e_; }
  const Eigen::Vector3d& antenna_arm_error_h() const { return ant_b_h_; }
  /// Start the antenna states at p_e, v_e with the given covariances (ECEF), independent of the rest, and take the
  /// white-acceleration PSD in the local level frame of p_e (eq. 10.1). The arm's error: a random constant, started at
  /// zero with covariance cov_b_h unless keep_arm_error (a re-initialization keeps what the run learnt).
  void init_antenna(const Eigen::Vector3d& p_e, const Eigen::Vector3d& v_e, const Eigen::Matrix3d& cov_p_e,
                    const Eigen::Matrix3d& cov_v_e, const Eigen::Matrix3d& cov_b_h);

  // P <- J P J^T with J = I except the (velocity, attitude) block = A (docs/fusion.md eq. 5.9).
  void reexpress_velocity_attitude(const Eigen::Matrix3d& A);
  static void reexpress_velocity_attitude(const Eigen::Matrix3d& A, ErrorMatrix& P_);

  // State i restarted as a fresh variable of the given variance, independent of everything before (clock, drift,
  // multipath slot): in P, in the smoother's Kalman-gain filter and in the smoother's interval (eq. 12.19).
  void restart_variable(int i, double variance);

  // Reset a clock to a new value with a large variance (receiver clock jump).
  void reset_clock(int slot, double value_m, double sigma_m);
  void reset_drift(double value_mps, double sigma_mps);

  /// Start a smoother interval at the current step (an output epoch, after all its updates; docs/fusion.md eq.
  /// 12.14); from here on every prediction, update, re-expression and reset is also applied to the interval.
  void smoother_restart();
  /// The backward record of the interval from the last smoother_restart() to the current step (eq. 12.20; with
  /// consider states eq. 12.24).
  void smoother_close(RtsSegment& out) const;
  /// Var and conditional mean of the error at the current step as the smoother sees them: the filter's P and 0, or
  /// with consider states the Kalman-gain filter's P_o and η (docs/fusion.md §12.6).
  const ErrorMatrix& smoother_P() const { return shadow_ ? Po_ : P_; }
  ErrorVector smoother_mean() const { return shadow_ ? eta_ : ErrorVector::Zero(P_.rows()); }
  /// Stop the smoother's bookkeeping (a re-initialization: the backward pass cannot cross it).
  void smoother_stop() { recording_ = false; }

  // check_covariance: also the symmetry / positive semi-definiteness test (an LDLT: done at the output epochs only).
  bool healthy(std::string& why, bool check_covariance) const;

  /// The IMU errors of the nominal state, their σ and the compensation totals (summary.json `imu_estimate`).
  ImuEstimate imu_estimate() const;

  /// Sum of the errors-in-variables corrections subtracted from scale state `state` so far (docs/consistency.md §3.6).
  double eiv_correction(int state) const;

  const ins::ErrorStateLayout& layout() const { return layout_; }
  ins::InsState& x() { return x_; }
  const ins::InsState& x() const { return x_; }
  const ErrorMatrix& P() const { return P_; }
  double clock(int slot) const { return clock_m_[slot]; }
  double drift() const { return drift_mps_; }
  int clock_offset(int slot) const { return clock_blocks_[slot].offset; }
  int drift_offset() const { return drift_block_.offset; }

 private:
  const EngineOptions& o_;
  const ins::ImuSpec spec_;  // the IMU error model the filter uses (filter_spec)
  ins::ErrorStateLayout layout_;
  std::string problem_;
  std::vector<ins::Block> clock_blocks_;
  ins::Block drift_block_{0, 0};
  ins::InsState x_;
  ins::DiscreteErrorModel model_;  // Φ, Q_d of the current step (reused: no per-step construction)
  Eigen::Vector3d sat_att_var_b_ = Eigen::Vector3d::Zero();  // pending saturation noise (add_saturation_noise), body axes
  Eigen::Vector3d sat_vel_var_b_ = Eigen::Vector3d::Zero();
  bool saturation_noise_ = false;
  ErrorMatrix P_;
  ErrorMatrix tmp_;
  std::vector<double> clock_m_;
  double drift_mps_ = 0.0;
  // Code multipath Gauss-Markov states (docs/consistency.md §3): block, nominal values, satellite and last epoch.
  static constexpr int64_t kNeverNs = std::numeric_limits<int64_t>::min();
  ins::Block mp_block_{0, 0};
  int g_sens_offset_ = -1;  // g-sensitivity block (docs/error_state.md §5), −1 without it
  ConsiderStates consider_;  // states the updates never correct (Schmidt–Kalman): the g-sensitivity block
  std::vector<double> mp_value_;
  ins::Block amb_block_{0, 0};    // carrier-phase ambiguity slots (random constants: Φ = 1, no process noise)
  std::vector<double> amb_value_;
  ins::Block ant_block_{0, 0};  // antenna position and velocity errors (ECEF) and the arm's error (heading frame): 9
  Eigen::Vector3d ant_p_e_ = Eigen::Vector3d::Zero(), ant_v_e_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d ant_b_h_ = Eigen::Vector3d::Zero();  // the arm's error, heading frame (random constant)
  Eigen::Matrix3d ant_q_e_ = Eigen::Matrix3d::Zero();  // white-acceleration PSD [m²/s³], ECEF
  std::vector<gnss::SatId> mp_sat_;
  std::vector<int64_t> mp_last_ns_;
  RowTransition<ins::kMaxErrorDim> Phi_rows_;  // Φ of the current step by its row structure
  // The rows of Φ that can have off-diagonal entries: position, velocity, attitude (docs/error_state.md eq. 3.1-3.8)
  // and the clocks (clock += drift dt); every other state is a random walk or Gauss-Markov state (RowTransition).
  int dense_rows_[ins::kMaxErrorDim];
  int n_dense_rows_ = 0, n_dense_rows_ins_ = 0;  // all; those before the first clock (the footprints' INS block)
  // Errors-in-variables compensation of the scale-factor estimates (docs/consistency.md §3.6). The scale column of
  // Φ is built from the measured increment, whose white noise ν also drives the error state: the noise part of
  // P's column of scale state s and the noise part of the error are both Σ_k g_k ν_k (times P_ss), so every update
  // moves ŝ by E[K_s r] = tr(S⁻¹ H M Hᵀ) on average, M = Σ_k P_ss σ_ν² g_k g_kᵀ (eq. E.4). M propagates like a
  // covariance (Φ M Φᵀ + input, (I − K H) M (I − K H)ᵀ at updates) and that mean is subtracted.
  static constexpr int kMaxEivTerms = 6;
  struct EivTerm {
    int state;         // scale state index
    int block_offset;  // error block the sensor noise enters: attitude (gyro) or velocity (accelerometer)
    int axis;          // body axis
    bool gyro;
    double total = 0.0;
  };
  // The footprints M_t of all terms, stacked: block t is rows [t n, (t + 1) n) of one column-major (count n) × n
  // array (leading dimension count · n), so the products that share Φ or H (M Φ_Gᵀ, Φ_G U, M Hᵀ) run once over all
  // blocks (RowTransition::propagate_stacked); every block gets the arithmetic it had as a matrix of its own.
  struct EivStack {
    int n = 0, count = 0;
    std::vector<double> s, u, ut, zt;  // footprints; scratch
    // Sized once (no allocation when a re-initialization keeps the size); u holds M Hᵀ of up to
    // kEivScratchRows measurement rows.
    static constexpr int kEivScratchRows = 64;
    void reset(int dim, int terms) {
      n = dim;
      count = terms;
      const size_t nn = static_cast<size_t>(terms) * dim * dim;
      s.assign(nn, 0.0);
      u.resize(static_cast<size_t>(terms) * dim * std::max(dim, kEivScratchRows));
      ut.resize(nn);
      zt.resize(nn);
    }
    Eigen::Index ld() const { return static_cast<Eigen::Index>(count) * n; }
    Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> block(int t) {
      return {s.data() + static_cast<Eigen::Index>(t) * n, n, n, Eigen::OuterStride<>(ld())};
    }
  };
  std::vector<EivTerm> eiv_;
  std::vector<EivTerm> eivo_;  // the same for the smoother's Kalman-gain filter (consider states, docs/fusion.md §12.6)
  EivStack eiv_stack_, eivo_stack_;
  int eiv_dim_ = 0;
  RowTransition<ins::kMaxErrorDim> eiv_Phi_;  // the INS block of Φ (footprints over the INS states only)

  void eiv_predict(double dt, const ins::NavState& before, const ins::NavState& after, std::vector<EivTerm>& terms,
                   EivStack& stack, const ErrorMatrix& P);

  // The mean noise-noise part of K_s r for every term (the forward filter's or the smoother's Kalman-gain filter's),
  // tr(S⁻¹ H M_t Hᵀ), into bias[], and M_t ← (I − K H) M_t (I − K H)ᵀ. H of a ZUPT or GNSS epoch touches a few states
  // only: U = M Hᵀ is summed over H's non-zero columns for all blocks at once (columns of the stack through
  // core/vector_kernels), B = H U per block; S⁻¹ (symmetric) is formed once.
  template <typename MatH, typename Ldlt, typename MatK>
  void eiv_update_all(std::vector<EivTerm>& terms, EivStack& st, const MatH& H, const Ldlt& S_ldlt, const MatK& K,
                      double* bias) {
    if (terms.empty()) return;
    const int ne = st.n, m = static_cast<int>(H.rows());
    if (ne > H.cols()) {
      for (size_t j = 0; j < terms.size(); ++j) bias[j] = 0.0;
      return;
    }
    int nz[ins::kMaxErrorDim];
    const int n_nz = nonzero_columns(H, nz);
    using SMat = Eigen::Matrix<double, MatH::RowsAtCompileTime, MatH::RowsAtCompileTime, Eigen::ColMajor,
                               MatH::MaxRowsAtCompileTime, MatH::MaxRowsAtCompileTime>;
    using UMat = Eigen::Matrix<double, Eigen::Dynamic, MatH::RowsAtCompileTime, Eigen::ColMajor, ins::kMaxErrorDim,
                               MatH::MaxRowsAtCompileTime>;
    SMat S_inv = SMat::Identity(H.rows(), H.rows());
    S_ldlt.solveInPlace(S_inv);  // once per update, shared by the terms
    const Eigen::Index ld = st.ld();
    if (st.u.size() < static_cast<size_t>(ld * m)) st.u.resize(static_cast<size_t>(ld * m));  // > 64 rows only
    double* const u_all = st.u.data();
    std::fill(u_all, u_all + ld * m, 0.0);
    for (int i = 0; i < m; ++i) {  // M Hᵀ of every block
      for (int k = 0; k < n_nz && nz[k] < ne; ++k) {
        const double h = H(i, nz[k]);
        if (h != 0.0) kernels::axpy1(ld, h, st.s.data() + nz[k] * ld, u_all + i * ld);
      }
    }
    UMat U(ne, m);
    SMat B;
    for (int t = 0; t < st.count; ++t) {
      for (int i = 0; i < m; ++i) U.col(i) = Eigen::Map<const Eigen::VectorXd>(u_all + i * ld + t * ne, ne);
      B.setZero(m, m);  // H M Hᵀ = H U
      for (int k = 0; k < n_nz && nz[k] < ne; ++k) B.noalias() += H.col(nz[k]) * U.row(nz[k]);
      bias[t] = S_inv.cwiseProduct(B).sum();  // tr(S⁻¹ B) with S⁻¹ and B symmetric
      // (I − K H) M (I − K H)ᵀ on the footprint's states: the noise-free form (R = 0) of the Joseph update.
      auto M = st.block(t);
      gain_downdate(M, U, K.topRows(ne), B);
    }
  }
  // Subtract the mean noise parts from the correction dx (docs/consistency.md eq. E.4) and, with shift_interval,
  // remove the same bias from the smoother interval's mean: in every component by regression on the scale states
  // (eq. E.7; P: the covariance after the update of the filter whose residual the interval conditions on), or in
  // the scale rows only (eq. E.6) — without either, its scale estimate at the interval's start would take the
  // subtraction back.
  void eiv_subtract(std::vector<EivTerm>& terms, const double* bias, ErrorVector& dx, bool shift_interval,
                    const ErrorMatrix& P);

  // Smoother: the interval since the last output epoch (docs/fusion.md eqs. 12.14-12.20), kept from the first
  // output epoch on.
  bool recording_ = false;
  RtsInterval interval_;
  // With consider states: the Kalman-gain filter of the same linearization that the smoother runs on (docs/fusion.md
  // §12.6): its covariance P_o = Var(δx | Y) and the conditional mean η = E[δx | Y] of the forward filter's error.
  bool shadow_ = false;
  ErrorMatrix Po_;
  ErrorVector eta_, eta_tmp_;
};
}  // namespace pednav::fusion
