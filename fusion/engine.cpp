#include "fusion/engine.hpp"

#include "fusion/health.hpp"
#include "fusion/kalman.hpp"
#include "fusion/lever_arm.hpp"
#include "fusion/rts.hpp"
#include "fusion/stride_velocity.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <type_traits>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "gnss/ephemeris.hpp"
#include "gnss/epoch_matching.hpp"
#include "gnss/least_squares.hpp"
#include "ins/alignment.hpp"
#include "ins/mechanization.hpp"
#include "ins/saturation.hpp"

namespace pednav::fusion {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;
/// Three measurement rows over the error state (fixed-capacity: no heap allocation in the update loop).
using Rows3 = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor, 3, ins::kMaxErrorDim>;

// Plausibility bounds of the nominal state (health check): 6250..6500 km from the centre covers every point from
// below the Dead Sea to 120 km altitude at any latitude; 100 m/s is far above any foot speed.
constexpr double kMinRadius_m = 6.25e6;
constexpr double kMaxRadius_m = 6.5e6;
constexpr double kMaxSpeed_mps = 100.0;
// ins mode: yaw σ kept inside the filter; the rest of the configured initial heading σ is a frame rotation carried
// outside it (docs/fusion.md §5.5). Small but non-zero so that P stays positive definite from the first epoch.
constexpr double kInsFilterSigmaYawRad = 0.1 * 3.14159265358979323846 / 180.0;
// The first still period's mean rate is taken as the initial gyro bias when its d² (docs/ins.md eq. 6.1) is within
// the χ²(3) quantile at this probability.
constexpr double kStillGyroBiasGateProbability = 0.999;

// Heading-frame uncertainty of an ins-mode run: variance of a rotation about up_e through origin_e [rad², m].
struct FrameYaw {
  double var_rad2 = 0.0;
  Vector3d origin_e = Vector3d::Zero();
  Vector3d up_e = Vector3d::UnitZ();
};
// Divergence with a healthy-looking state and covariance (docs/robustness.md): innovations implausible for this many
// consecutive GNSS epochs, each with at least kImplausibleMinCodeRows code rows of which more than half were rejected.
constexpr int kImplausibleEpochs = 10;
constexpr int kImplausibleMinCodeRows = 5;
// Re-initialization from a GNSS epoch solution after divergence (tc mode): at most this many per run; the attitude is
// the last healthy stance attitude, its heading may be off (wide σ), the walker's velocity is unknown.
constexpr int kMaxReinitializations = 5;
constexpr double kReinitSigmaYawRad = 30.0 * 3.14159265358979323846 / 180.0;
constexpr double kReinitSigmaVelMps = 2.0;
constexpr double kReinitSigmaPosM = 10.0;  // an epoch least-squares position (single epoch, possibly undifferenced)
// The restart happens during a stance (foot flat and still: the last stance attitude and zero velocity hold there)
// with a GNSS epoch solution at most this old [s] (the walker moves ~1.5 m/s: well inside kReinitSigmaPosM).
constexpr double kReinitMaxFixAgeS = 2.0;

// A GNSS epoch solution kept for a re-initialization: antenna position [m] ECEF at GPST t, satellites in the epoch.
struct PendingFix {
  GpsTime t;
  Vector3d p_ea_e;
  size_t n_sats = 0;
};
// GNSS update rows held in fixed-capacity matrices (32 satellites with code + Doppler); more use dynamic ones.
constexpr int kMaxGnssRows = 64;

// Persistent-fault test (docs/fusion.md §6.2): one satellite's code w of its last consecutive GNSS epochs.
struct FaultHistory {
  gnss::SatId sat;
  long epoch = -1;  // the engine's GNSS epoch count at the newest entry
  int count = 0;    // valid entries in w (newest first)
  std::array<double, kMaxFaultWindowEpochs - 1> w{};
};

// The entry of `sat` in `histories` (const or not), or its end.
template <typename Histories>
auto find_fault_history(Histories& histories, const gnss::SatId& sat) {
  return std::find_if(histories.begin(), histories.end(), [&](const FaultHistory& e) { return e.sat == sat; });
}

int system_slot(const std::vector<gnss::System>& systems, gnss::System s) {
  for (size_t i = 0; i < systems.size(); ++i) {
    if (systems[i] == s) return static_cast<int>(i);
  }
  return -1;
}

// One candidate GNSS measurement row with its noise.
struct Row {
  gnss::SatId sat;
  bool doppler = false;
  double residual = 0.0;
  ins::ErrorRowVector h;
  double sigma = 0.0;
  /// ∂(predicted)/∂(antenna position) for code rows, ∂/∂(antenna velocity) for Doppler rows: projects the
  /// non-rigid arm's offset / velocity noise common to all satellites into R.
  Eigen::RowVector3d j_antenna = Eigen::RowVector3d::Zero();
};

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

// The filter state: nominal INS state + differential clocks, error covariance. Matrices have a fixed capacity
// (ins::ErrorMatrix): nothing here allocates on the heap per step (docs/performance.md).
class Filter {
 public:
  Filter(const EngineOptions& o, int n_clocks) : o_(o), spec_(filter_spec(o)) {
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
          eiv_.push_back(EivTerm{b->offset + axis, gyro ? ins::kAtt.offset : ins::kVel.offset, axis, gyro, {}});
        }
      }
    }
    clock_m_.assign(n_clocks, 0.0);
  }

  /// Why the filter cannot run (e.g. more states than ins::kMaxErrorDim), empty if it can.
  const std::string& problem() const { return problem_; }

  void init(const ins::NavState& nav, const ins::ImuErrors& imu, double sigma_yaw_rad) {
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
    for (int i = 0; i < mp_block_.dim; ++i) {  // unit-variance GM, no satellite yet (also at a re-initialization)
      P_(mp_block_.offset + i, mp_block_.offset + i) = 1.0;
      mp_value_[i] = 0.0;
      mp_last_ns_[i] = kNeverNs;
    }
    // The footprints are kept on the INS states only (core and scale: the leading block of the layout), not on
    // the clocks and multipath states the GNSS updates also correlate them with (docs/consistency.md §3.7: the
    // subtracted totals change by < 2 % on the large ones, 5 % on the smallest, at about half the cost).
    eiv_dim_ = clock_blocks_.empty() ? layout_.dim() : clock_blocks_.front().offset;
    for (auto& t : eiv_) t.M.setZero(eiv_dim_, eiv_dim_);  // no noise footprint yet (also at a re-init)
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
      for (auto& t : eivo_) t.M.setZero(layout_.dim(), layout_.dim());
    }
  }

  // Replace the variance of a 3-state block (position [m], velocity [m/s]) by sigma² per axis, uncorrelated
  // (re-initialization).
  void set_block_sigma(const ins::Block& b, double sigma) {
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

  // Mechanize one (already bias-corrected) increment and propagate the covariance.
  void predict(const ins::ImuIncrement& inc) {
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
    Phi_sparse_.assign(m.Phi);
    // Smoother: the cross-covariance of the error at the last output epoch with the current error, Γ ← Γ Φᵀ
    // (docs/fusion.md eq. 12.15).
    if (recording_) interval_.predict(Phi_sparse_);
    if (!eiv_.empty()) eiv_predict(inc.dt_s, x_.nav, after, eiv_, P_);
    if (shadow_ && !eivo_.empty()) eiv_predict(inc.dt_s, x_.nav, after, eivo_, Po_);
    if (shadow_) {  // the Kalman-gain filter of the smoother (docs/fusion.md eq. 12.22): η ← Φ η, P_o ← Φ P_o Φᵀ + Q_d
      Phi_sparse_.times(eta_, eta_tmp_);
      eta_ = eta_tmp_;
      covariance_predict(Po_, Phi_sparse_, m.Qd, tmp_);
    }
    covariance_predict(P_, Phi_sparse_, m.Qd, tmp_);
    x_.nav = after;
  }

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
      eiv_update_all(eiv_, H, S_ldlt, K, eiv_bias);
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
            eiv_update_all(eivo_, H, So_ldlt, Ko, eivo_bias);
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

  void apply(const ErrorVector& dx) {
    x_ = ins::boxplus(x_, dx, layout_);
    for (size_t i = 0; i < clock_blocks_.size(); ++i) clock_m_[i] += dx(clock_blocks_[i].offset);
    if (o_.mode == Mode::kTightlyCoupled) drift_mps_ += dx(drift_block_.offset);
    for (int i = 0; i < mp_block_.dim; ++i) mp_value_[i] += dx(mp_block_.offset + i);
  }

  /// The multipath state of satellite `sat` measured at rover epoch t_ns [GPST ns]: its slot, or (satellite new, or
  /// not measured for longer than multipath_reset_gap_s) a slot restarted as a fresh unit-variance state — the
  /// least recently used slot not yet used at this epoch. `reset` tells whether it was restarted. -1 when every slot
  /// is in use at this epoch (that satellite's code is then treated as white, docs/consistency.md §3).
  int multipath_slot(const gnss::SatId& sat, int64_t t_ns, bool& reset) {
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
  /// First state of the g-sensitivity block (column-major G_g), −1 without it.
  int g_sensitivity_offset() const { return g_sens_offset_; }
  /// State index of multipath slot `slot`; its nominal value u (closed loop: normally 0 after each update, decayed).
  int multipath_index(int slot) const { return mp_block_.offset + slot; }
  double multipath_value(int slot) const { return mp_value_[slot]; }
  bool has_multipath() const { return mp_block_.dim > 0; }

  // P <- J P J^T with J = I except the (velocity, attitude) block = A (docs/fusion.md eq. 5.9).
  void reexpress_velocity_attitude(const Eigen::Matrix3d& A) {
    reexpress_velocity_attitude(A, P_);
    if (shadow_) {  // the smoother's Kalman-gain filter: P_o ← J P_o Jᵀ, η ← J η
      reexpress_velocity_attitude(A, Po_);
      const Vector3d eta_att = eta_.segment<3>(ins::kAtt.offset);
      eta_.segment<3>(ins::kVel.offset) += A * eta_att;
    }
    // The smoother's cross-covariance follows the coordinate change: Γ ← Γ Jᵀ (docs/fusion.md eq. 12.18).
    if (recording_) interval_.reexpress(ins::kVel.offset, ins::kAtt.offset, A);
  }
  static void reexpress_velocity_attitude(const Eigen::Matrix3d& A, ErrorMatrix& P_) {
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

  // State i restarted as a fresh variable of the given variance, independent of everything before (clock, drift,
  // multipath slot): in P, in the smoother's Kalman-gain filter and in the smoother's interval (eq. 12.19).
  void restart_variable(int i, double variance) {
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

  // Reset a clock to a new value with a large variance (receiver clock jump).
  void reset_clock(int slot, double value_m, double sigma_m) {
    const int c = clock_blocks_[slot].offset;
    clock_m_[slot] = value_m;
    restart_variable(c, sigma_m * sigma_m);
  }
  void reset_drift(double value_mps, double sigma_mps) {
    const int d = drift_block_.offset;
    drift_mps_ = value_mps;
    restart_variable(d, sigma_mps * sigma_mps);
  }

  /// Start a smoother interval at the current step (an output epoch, after all its updates; docs/fusion.md eq.
  /// 12.14); from here on every prediction, update, re-expression and reset is also applied to the interval.
  void smoother_restart() {
    if (shadow_) {
      interval_.restart(Po_, eta_);  // eq. 12.21
    } else {
      interval_.restart(P_);
    }
    recording_ = true;
  }
  /// The backward record of the interval from the last smoother_restart() to the current step (eq. 12.20; with
  /// consider states eq. 12.24).
  void smoother_close(RtsSegment& out) const {
    if (shadow_) {
      interval_.close(Po_, eta_, out);
    } else {
      interval_.close(P_, out);
    }
  }
  /// Var and conditional mean of the error at the current step as the smoother sees them: the filter's P and 0, or
  /// with consider states the Kalman-gain filter's P_o and η (docs/fusion.md §12.6).
  const ErrorMatrix& smoother_P() const { return shadow_ ? Po_ : P_; }
  ErrorVector smoother_mean() const { return shadow_ ? eta_ : ErrorVector::Zero(P_.rows()); }
  /// Stop the smoother's bookkeeping (a re-initialization: the backward pass cannot cross it).
  void smoother_stop() { recording_ = false; }

  // check_covariance: also the symmetry / positive semi-definiteness test (an LDLT: done at the output epochs only).
  bool healthy(std::string& why, bool check_covariance) const {
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

  /// The IMU errors of the nominal state, their σ and the compensation totals (summary.json `imu_estimate`).
  ImuEstimate imu_estimate() const {
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

  /// Sum of the errors-in-variables corrections subtracted from scale state `state` so far (docs/consistency.md §3.6).
  double eiv_correction(int state) const {
    for (const auto& t : eiv_) {
      if (t.state == state) return t.total;
    }
    return 0.0;
  }

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
  Vector3d sat_att_var_b_ = Vector3d::Zero();  // pending saturation noise (add_saturation_noise), body axes
  Vector3d sat_vel_var_b_ = Vector3d::Zero();
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
  std::vector<gnss::SatId> mp_sat_;
  std::vector<int64_t> mp_last_ns_;
  ColumnSparse<ins::kMaxErrorDim> Phi_sparse_;
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
    ErrorMatrix M;
    double total = 0.0;
  };
  std::vector<EivTerm> eiv_;
  std::vector<EivTerm> eivo_;  // the same for the smoother's Kalman-gain filter (consider states, docs/fusion.md §12.6)
  ErrorMatrix eiv_tmp_, eiv_zero_;
  int eiv_dim_ = 0;
  ColumnSparse<ins::kMaxErrorDim> eiv_Phi_;

  void eiv_predict(double dt, const ins::NavState& before, const ins::NavState& after, std::vector<EivTerm>& terms,
                   const ErrorMatrix& P) {
    const int n = terms.empty() ? 0 : static_cast<int>(terms.front().M.rows());
    if (eiv_zero_.rows() != n) eiv_zero_.setZero(n, n);
    if (n != layout_.dim()) eiv_Phi_.assign(model_.Phi.topLeftCorner(n, n));
    const auto& Phi = n != layout_.dim() ? eiv_Phi_ : Phi_sparse_;
    const Eigen::Matrix3d R = before.q_e_b.slerp(0.5, after.q_e_b).toRotationMatrix();
    // The noise ν_u of every scale term u's regressor enters P's column of scale state t through P_tu (its own column
    // of Φ times P_{s_u s_t}), and the error through g_u: M_t gains Σ_u P_tu σ_u² Δt g_u g_uᵀ (docs/consistency.md
    // eq. E.5; only u = t in session 9).
    for (auto& t : terms) {
      covariance_predict(t.M, Phi, eiv_zero_, eiv_tmp_);
      for (const auto& u : terms) {
        const double psd = u.gyro ? spec_.gyro_arw * spec_.gyro_arw : spec_.accel_vrw * spec_.accel_vrw;
        const Vector3d g = R.col(u.axis);
        t.M.block<3, 3>(u.block_offset, u.block_offset).noalias() +=
            (P(t.state, u.state) * psd * dt) * (g * g.transpose());
      }
    }
  }

  // eiv_update for every term of `terms` (the forward filter's or the smoother's Kalman-gain filter's) into bias[].
  template <typename MatH, typename Ldlt, typename MatK>
  void eiv_update_all(std::vector<EivTerm>& terms, const MatH& H, const Ldlt& S_ldlt, const MatK& K, double* bias) {
    if (terms.empty()) return;
    int nz[ins::kMaxErrorDim];
    const int n_nz = nonzero_columns(H, nz);
    for (size_t j = 0; j < terms.size(); ++j) bias[j] = eiv_update(terms[j].M, H, nz, n_nz, S_ldlt, K);
  }
  // Subtract the mean noise parts from the correction dx (docs/consistency.md eq. E.4) and, with shift_interval,
  // remove the same bias from the smoother interval's mean: in every component by regression on the scale states
  // (eq. E.7; P: the covariance after the update of the filter whose residual the interval conditions on), or in
  // the scale rows only (eq. E.6) — without either, its scale estimate at the interval's start would take the
  // subtraction back.
  void eiv_subtract(std::vector<EivTerm>& terms, const double* bias, ErrorVector& dx, bool shift_interval,
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

  // The mean noise-noise part of K_s r for one scale state, tr(S⁻¹ H M Hᵀ), and M ← (I − K H) M (I − K H)ᵀ. H of a
  // ZUPT or GNSS epoch touches a few states only: M Hᵀ is summed over H's non-zero columns nz[0..n_nz).
  template <typename MatH, typename Ldlt, typename MatK>
  double eiv_update(ErrorMatrix& M, const MatH& H, const int* nz, int n_nz, const Ldlt& S_ldlt, const MatK& K) {
    const int ne = static_cast<int>(M.rows());
    if (ne > H.cols()) return 0.0;
    using UMat = Eigen::Matrix<double, Eigen::Dynamic, MatH::RowsAtCompileTime, Eigen::ColMajor, ins::kMaxErrorDim,
                               MatH::MaxRowsAtCompileTime>;
    using SMat = Eigen::Matrix<double, MatH::RowsAtCompileTime, MatH::RowsAtCompileTime, Eigen::ColMajor,
                               MatH::MaxRowsAtCompileTime, MatH::MaxRowsAtCompileTime>;
    UMat U;  // M Hᵀ
    U.setZero(ne, H.rows());
    for (int k = 0; k < n_nz && nz[k] < ne; ++k) U.noalias() += M.col(nz[k]) * H.col(nz[k]).head(ne).transpose();
    SMat B;  // H M Hᵀ
    B.noalias() = H.leftCols(ne) * U;
    const double bias = S_ldlt.solve(B).trace();
    // (I − K H) M (I − K H)ᵀ on the INS block: the noise-free form (R = 0) of the Joseph update.
    gain_downdate(M, U, K.topRows(ne), B);
    return bias;
  }
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

// Median of v (reorders v; no copy).
double median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

struct PassOptions {
  bool gnss = true;
  std::optional<GpsTime> stop;
  /// The heading pass: each time the IMU has walked the next milestone (walked_milestone_m, then twice that, …) —
  /// horizontal path length of the nominal position over the samples the detector does not flag as stance, so ZUPT
  /// corrections at rest do not count and the distance does not depend on the unknown heading — at_milestone(the
  /// outputs so far, the milestone) is called; the pass stops when it returns true.
  double walked_milestone_m = 0.0;
  std::function<bool(const EngineResult&, double)> at_milestone;
};

class Runner {
 public:
  Runner(const EngineInputs& in, const EngineOptions& o, const std::vector<ins::ZuptDecision>& decisions)
      : in_(in), o_(o), decisions_(decisions),
        // The w-test threshold depends on the configured probability only: computed once (a bisection on the
        // incomplete gamma function), not at every GNSS epoch.
        w_test_threshold_(gnss::chi_square_quantile(o.fault_probability, 1)),
        zaru_gate_threshold_(o.zaru_gate_probability > 0.0 ? gnss::chi_square_quantile(o.zaru_gate_probability, 3) : 0.0) {
    if (o.mode == Mode::kTightlyCoupled && in.rover && in.base && o.base_position_e) {
      std::vector<GpsTime> rt, bt;
      for (const auto& e : *in.rover) rt.push_back(e.time);
      for (const auto& e : *in.base) bt.push_back(e.time);
      matches_ = gnss::match_base_epochs(rt, bt, o.max_base_age_s);
      sd_ = true;
    }
    // Per-epoch buffers sized once for the largest epoch (no reallocation on the per-epoch path).
    size_t max_sats = 0;
    if (in.rover) {
      for (const auto& e : *in.rover) max_sats = std::max(max_sats, e.sats.size());
    }
    if (in.imu) {
      // The stance samples a ZUPT may use; the core of a short stance spans one mechanization interval, so that
      // every detected stance keeps at least one update.
      zupt_ok_ = ins::zupt_update_samples(decisions, *in.imu, o.zupt_edge_s, 1.0 / o.mechanization_rate_hz);
    }
    if (o.repair_saturation && in.imu) {
      ins::SaturationOptions so;
      so.gyro_range_radps = o.spec.gyro_range;
      so.accel_range_mps2 = o.spec.accel_range;
      saturation_ = ins::repair_saturation(*in.imu, so);
    }
    re_.sats.reserve(max_sats);
    rows_.reserve(2 * max_sats);
    code_res_by_slot_.resize(o.systems.size());
    for (auto& v : code_res_by_slot_) v.reserve(max_sats);
    doppler_res_.reserve(max_sats);
    active_.reserve(2 * max_sats);
  }

  Vector3d lever_e(const Vector3d& p_e) const {
    const Geodetic llh = geodetic_from_ecef(p_e);
    return R_e_n(llh.lat, llh.lon) * o_.lever_arm_n_m;
  }

  // Epoch LSQ antenna position (used for initialization, the heading fit and re-initialization).
  // allow_undifferenced: an epoch without a base epoch is solved undifferenced instead of skipped.
  std::optional<Vector3d> lsq_position(size_t rover_index, const Vector3d& p_init, bool allow_undifferenced = false) const {
    if (!in_.nav || !in_.rover) return std::nullopt;
    const gnss::ObsEpoch& re = (*in_.rover)[rover_index];
    const gnss::ObsEpoch* be = nullptr;
    if (sd_) {
      if (matches_[rover_index].base_index >= 0) be = &(*in_.base)[matches_[rover_index].base_index];
      else if (!allow_undifferenced) return std::nullopt;
    }
    gnss::SolverOptions so;
    so.elevation_mask_rad = o_.elevation_mask_rad;
    so.min_cn0_dbhz = o_.min_cn0_dbhz;
    so.weights = o_.weights;
    so.fault_probability = o_.fault_probability;
    gnss::ObsEpoch filtered = re;
    std::erase_if(filtered.sats, [&](const gnss::SatObs& s) { return system_slot(o_.systems, s.sat.system) < 0; });
    if (in_.gnss_mask) in_.gnss_mask(filtered);
    const auto sol = gnss::solve_epoch(*in_.nav, filtered, be, o_.base_position_e.value_or(Vector3d::Zero()), p_init, so);
    if (!sol.ok()) return std::nullopt;
    return sol.p_ea_e;
  }

  // Run the filter from sample `start` with the given initial state; fills result (outputs + summary).
  Expected<void> run(size_t start, const ins::NavState& nav0, const ins::ImuErrors& imu0, const PassOptions& po,
                     EngineResult& result) {
    const auto& samples = *in_.imu;
    Filter f(o_, static_cast<int>(o_.systems.size()));
    if (!f.problem().empty()) return make_error(f.problem());
    // ins mode: an initial heading error only rotates the whole trajectory about the start point — no ZUPT or ZARU
    // observes it (H_D s = 0 for the rotation direction s, docs/fusion.md §5.5). Its variance is carried outside the
    // filter and added to the reported covariance; inside, a large yaw variance would only turn ZUPT model errors
    // (residual foot motion at stance onset) into heading jumps.
    frame_ = FrameYaw{};
    double filter_sigma_yaw_rad = o_.initial_sigma_yaw_rad;
    if (o_.mode == Mode::kInsOnly && o_.ins_heading_as_frame && filter_sigma_yaw_rad > kInsFilterSigmaYawRad) {
      frame_.var_rad2 = filter_sigma_yaw_rad * filter_sigma_yaw_rad - kInsFilterSigmaYawRad * kInsFilterSigmaYawRad;
      frame_.origin_e = nav0.p_eb_e;
      frame_.up_e = R_e_n(geodetic_from_ecef(nav0.p_eb_e).lat, geodetic_from_ecef(nav0.p_eb_e).lon).col(2) * -1.0;
      filter_sigma_yaw_rad = kInsFilterSigmaYawRad;
    }
    f.init(nav0, imu0, filter_sigma_yaw_rad);
    stride_.reset();
    EngineSummary& sum = result.summary;
    if (o_.mode == Mode::kTightlyCoupled) {
      // The outcomes every epoch can have exist from the start (0 until they happen): a first rejection later in
      // the run then does not allocate a map node on the per-epoch path (tests/fusion/test_allocations.cpp).
      for (auto* m : {&sum.code_used_rejected, &sum.doppler_used_rejected}) {
        m->try_emplace("used", 0);
        m->try_emplace("innovation_fault", 0);
      }
      sum.code_used_rejected.try_emplace("persistent_fault", 0);
      fault_history_.reserve(static_cast<size_t>(kMaxGnssRows));
    }
    // Smoother (docs/fusion.md §12): one backward record per output epoch, carried forward from each output epoch
    // to the next by the filter (eqs. 12.14-12.20).
    // Consider states (the g-sensitivity, docs/error_state.md §5) leave the forward error with a non-zero conditional
    // mean: the smoother then runs on the Kalman-gain filter of the same linearization (§12.6).
    const bool smooth = o_.smoother_enabled;
    const int n_state = f.layout().dim();
    RtsSegment segment;
    RtsStore segments(n_state);
    std::vector<ins::InsState> nominal_at_output;
    // Storage sized once from the data span (no reallocation on the per-epoch path; docs/performance.md).
    const double span_s = std::max(0.0, in_.imu->back().t - nav0.t);
    const size_t expected_outputs = static_cast<size_t>(span_s * o_.output_rate_hz) + 2;
    result.epochs.reserve(result.epochs.size() + expected_outputs);
    if (smooth) {
      segments.reserve(expected_outputs);
      nominal_at_output.reserve(expected_outputs);
    }
    if (o_.record_gnss_rows && in_.rover) result.gnss_rows.reserve(result.gnss_rows.size() + in_.rover->size() * rows_.capacity());
    bool segment_open = false;
    ins::IncrementOptions io;
    io.rate_hz = o_.mechanization_rate_hz;
    ins::IncrementIntegrator integrator(io);
    const int64_t out_period_ns = static_cast<int64_t>(std::llround(1e9 / o_.output_rate_hz));
    int64_t next_out_ns = ((nav0.t.ns() + out_period_ns - 1) / out_period_ns) * out_period_ns;
    size_t gi = 0;
    bool clock_initialized = false;
    const bool gnss_pass = po.gnss && o_.mode == Mode::kTightlyCoupled && in_.rover;
    if (in_.rover) {
      while (gi < in_.rover->size() && (*in_.rover)[gi].time < nav0.t) {
        if (gnss_pass) count(sum.gnss_skipped, "outside_imu_span", (*in_.rover)[gi].sats.size());
        ++gi;
        ++sum.gnss_epochs_before_start;
      }
    }
    size_t sample_index = start;
    int last_used = 0, last_rejected = 0;
    bool failed = false;
    int64_t last_covariance_check_ns = std::numeric_limits<int64_t>::min() / 2;
    bool prev_zupt = false;  // a ZUPT at the previous mechanization epoch (ZARU: the whole interval is stance)
    std::optional<StepTracker> steps;  // seed 000 step-velocity aiding (fusion/step_velocity.hpp)
    if (o_.step_velocity.enabled) steps.emplace(o_.step_velocity);
    std::string fail_message;
    // Recovery (docs/robustness.md): after a failed health check in tc mode the filter waits for the next GNSS epoch
    // that the epoch least squares solves and re-initializes there. The smoother cannot cross a re-initialization.
    const bool can_reinit = gnss_pass && in_.nav;
    bool waiting = false;
    std::optional<PendingFix> pending;  // the latest solvable GNSS epoch while waiting
    std::optional<GpsTime> reinitialized_at;
    ins::InsState last_stance = f.x();  // attitude and IMU errors to restart from
    implausible_streak_ = 0;

    auto on_increment = [&](const ins::ImuIncrement& inc) {
      if (failed || waiting) return;
      const Vector3d p_before = f.x().nav.p_eb_e;
      f.predict(inc);
      ++sum.mechanization_steps;
      // ZUPT (+ ZARU) when the detector flags the sample at the interval end as stance, away from the stance's
      // edges (zupt_edge_s, docs/zupt.md §5).
      const bool stance = decisions_[std::min(sample_index, decisions_.size() - 1)].stance;
      stride_.push(inc.t1.ns(), f.x().nav.p_eb_e - p_before, stance);  // mechanized displacement only (eq. 13.1)
      const bool zupt_now = stance && zupt_ok_[std::min(sample_index, zupt_ok_.size() - 1)];
      if (zupt_now && o_.zupt_updates) {
        zupt_update(f, inc, prev_zupt, sum);
        ++sum.zupt_updates;
      }
      if (steps) {
        if (auto m = steps->push(f.x().nav, inc.dt_s, stance)) step_velocity_update(f, *m, sum);
      }
      // GNSS epochs up to the interval end.
      while (po.gnss && o_.mode == Mode::kTightlyCoupled && in_.rover && gi < in_.rover->size() && (*in_.rover)[gi].time <= inc.t1) {
        gnss_update(f, gi, inc.t1, clock_initialized, sum, last_used, last_rejected,
                    o_.record_gnss_rows ? &result.gnss_rows : nullptr);
        ++gi;
      }
      prev_zupt = zupt_now;
      std::string why;
      const bool output_now = inc.t1.ns() >= next_out_ns;
      // The symmetry / PSD test (an LDLT) at output epochs, at most once per second (outputs at the mechanization
      // rate, as in the heading pass, would otherwise pay it every step); finiteness and variances every step.
      const bool check_covariance = output_now && inc.t1.ns() - last_covariance_check_ns >= kNsPerS;
      if (check_covariance) last_covariance_check_ns = inc.t1.ns();
      if (!f.healthy(why, check_covariance) || implausible_streak_ >= kImplausibleEpochs) {
        if (why.empty()) {
          why = "innovations implausible: " + std::to_string(implausible_streak_) +
                " consecutive GNSS epochs with most code measurements rejected";
        }
        const std::string event = "filter diverged at " + inc.t1.to_string() + ": " + why;
        sum.covariance_healthy = false;
        sum.health_message = event;
        sum.health_events.push_back(event);
        if (can_reinit && sum.reinitializations < kMaxReinitializations) {
          waiting = true;
          return;
        }
        failed = true;
        fail_message = event;
        if (can_reinit) fail_message += " (after " + std::to_string(kMaxReinitializations) + " re-initializations)";
        return;
      }
      if (stance) last_stance = f.x();
      if (output_now) {
        while (next_out_ns <= inc.t1.ns()) next_out_ns += out_period_ns;
        result.epochs.push_back(output(f.x(), f.P(), inc.t1, stance, last_used, last_rejected));
        last_used = last_rejected = 0;
        if (smooth && !reinitialized_at) {
          if (segment_open) {
            f.smoother_close(segment);
            segments.push(segment);
          }
          f.smoother_restart();
          segment_open = true;
          nominal_at_output.push_back(f.x());
        }
      }
      if (in_.on_step) in_.on_step(inc.t1);
    };

    const Vector3d up_start_e = nav0.p_eb_e.normalized();
    Vector3d p_last_e = nav0.p_eb_e;
    double walked_m = 0.0, milestone_m = po.walked_milestone_m;
    auto stop_walking = [&] {
      const Vector3d d = f.x().nav.p_eb_e - p_last_e;
      p_last_e = f.x().nav.p_eb_e;
      if (!decisions_[std::min(sample_index, decisions_.size() - 1)].stance) {
        walked_m += (d - d.dot(up_start_e) * up_start_e).norm();
      }
      if (walked_m < milestone_m) return false;
      const double reached = milestone_m;
      milestone_m *= 2.0;
      return po.at_milestone(result, reached);
    };
    // Saturated samples (docs/ins.md §9): the repaired copies replace them; each run's σ goes into the filter
    // with the run's last sample.
    const auto& sat_samples = saturation_.samples;
    const auto& sat_runs = saturation_.runs;
    size_t sat_sample = 0, sat_run = 0;
    for (const auto& r : sat_runs) {
      if (r.last < start) continue;
      ++sum.saturated_runs;
      if (r.reconstructed) ++sum.saturated_runs_reconstructed;
      if (r.gyro) sum.saturation_max_added_deg = std::max(sum.saturation_max_added_deg, std::abs(r.added) * kRadToDeg);
    }
    for (const auto& s : sat_samples) sum.saturated_samples += s.index >= start ? 1 : 0;
    sum.saturation_notes = saturation_.notes;
    ins::ImuSample repaired;
    for (; sample_index < samples.size(); ++sample_index) {
      const ins::ImuSample* raw_ptr = &samples[sample_index];
      while (sat_sample < sat_samples.size() && sat_samples[sat_sample].index < sample_index) ++sat_sample;
      if (sat_sample < sat_samples.size() && sat_samples[sat_sample].index == sample_index) {
        repaired.t = raw_ptr->t;
        repaired.omega_ib_b = sat_samples[sat_sample].omega_ib_b;
        repaired.f_ib_b = sat_samples[sat_sample].f_ib_b;
        raw_ptr = &repaired;
      }
      while (sat_run < sat_runs.size() && sat_runs[sat_run].last < sample_index) ++sat_run;
      const ins::ImuSample& raw = *raw_ptr;
      if (po.stop && raw.t > *po.stop) break;
      if (po.at_milestone && milestone_m > 0.0 && stop_walking()) break;
      if (!raw.omega_ib_b.allFinite() || !raw.f_ib_b.allFinite()) {
        count(sum.imu_rejected, "non_finite");
        continue;
      }
      if (waiting) {
        const bool stance_now = decisions_[std::min(sample_index, decisions_.size() - 1)].stance;
        if (!reinitialize(f, raw.t, stance_now, gi, last_stance, pending, sum)) {
          count(sum.imu_skipped, "filter_diverged");
          continue;
        }
        waiting = false;
        reinitialized_at = raw.t;
        f.smoother_stop();
        integrator = ins::IncrementIntegrator(io);  // the increments restart at this sample
        clock_initialized = false;
        implausible_streak_ = 0;
        fault_history_.clear();  // innovations of the diverged filter are no evidence about the satellites
        prev_zupt = false;
        last_used = last_rejected = 0;
        stride_.reset();
        if (steps) steps.emplace(o_.step_velocity);
      }
      ++sum.imu_samples;
      for (; sat_run < sat_runs.size() && sat_runs[sat_run].last == sample_index; ++sat_run) {
        const auto& r = sat_runs[sat_run];
        f.add_saturation_noise(r.gyro, r.axis, r.sigma * r.sigma);
      }
      const ins::ImuSample corrected = ins::correct_sample(raw, f.x().imu);
      integrator.push(corrected, on_increment);
      if (failed) break;
    }
    if (pending) count(sum.gnss_skipped, "filter_diverged", pending->n_sats);
    sum.imu_estimate = f.imu_estimate();
    if (gnss_pass) {
      sum.gnss_epochs_before_start += static_cast<long>(in_.rover->size() - gi);
      for (size_t g = gi; g < in_.rover->size(); ++g) {
        count(sum.gnss_skipped, waiting ? "filter_diverged" : "outside_imu_span", (*in_.rover)[g].sats.size());
      }
    }
    if (waiting && !failed) {
      failed = true;
      fail_message = sum.health_message + "; no later GNSS epoch could be solved to re-initialize";
    }
    if (reinitialized_at && smooth) {
      sum.smoother_message = "not smoothed: the filter was re-initialized at " + reinitialized_at->to_string() +
                             " (the backward pass cannot cross a re-initialization)";
    }
    if (failed) {
      sum.covariance_healthy = false;
      sum.health_message = fail_message;
      return make_error(fail_message);
    }
    if (smooth && !reinitialized_at && !result.epochs.empty()) {
      // The tail: the last output epoch -> the last step (eq. 12.10).
      RtsSegment tail;
      f.smoother_close(tail);
      const size_t bytes = segments.bytes() + nominal_at_output.size() * sizeof(ins::InsState);
      result.smoothed.resize(result.epochs.size());
      bool finite = true;
      size_t bad = 0;
      rts_backward(segments, tail, f.smoother_P(), f.smoother_mean(), [&](size_t k, const ErrorVector& dx,
                                                                           const ErrorMatrix& P) {
        // Smoothed state = forward nominal ⊞ smoothed error (eq. 12.12).
        const ins::InsState xs = ins::boxplus(nominal_at_output[k], dx, f.layout());
        const EpochOutput& fwd = result.epochs[k];
        result.smoothed[k] = output(xs, P, fwd.t, fwd.zupt, fwd.n_sats_used, fwd.n_sats_rejected);
        if (finite && (!xs.nav.p_eb_e.allFinite() || !P.allFinite())) {
          finite = false;
          bad = k;
        }
      });
      if (!finite) {
        // The forward solution stands; the smoothed one is withheld and the reason reported.
        sum.smoother_message =
            "smoother diverged at " + result.epochs[bad].t.to_string() + ": non-finite smoothed state or covariance";
        result.smoothed.clear();
        return {};
      }
      sum.smoothed = true;
      sum.smoother_records = static_cast<long>(segments.size() + 1);
      sum.smoother_bytes = static_cast<long>(bytes);
    }
    return {};
  }

  // Re-initialization after divergence, called for each IMU sample (time t, GPST; stance: the detector's flag) while
  // waiting: rover epochs up to t are solved by the epoch least squares, the latest solution is kept in `pending`.
  // At a stance with a solution at most kReinitMaxFixAgeS old the filter restarts: position from GNSS (antenna -> IMU,
  // σ >= kReinitSigmaPosM), velocity zero (σ kReinitSigmaVelMps), attitude and IMU errors of `last_stance` (a flat
  // foot again) with a wide heading σ. A restart in mid-swing would take the stance attitude for a foot pitched by
  // tens of degrees. Epochs passed over are counted as skipped. True if re-initialized.
  bool reinitialize(Filter& f, GpsTime t, bool stance, size_t& gi, const ins::InsState& last_stance,
                    std::optional<PendingFix>& pending, EngineSummary& sum) {
    while (gi < in_.rover->size() && (*in_.rover)[gi].time <= t) {
      const size_t n_sats = (*in_.rover)[gi].sats.size();
      const Vector3d p_guess = pending ? pending->p_ea_e : last_stance.nav.p_eb_e + lever_e(last_stance.nav.p_eb_e);
      const std::optional<Vector3d> pa = lsq_position(gi, p_guess, /*allow_undifferenced=*/true);
      if (!pa) {
        count(sum.gnss_skipped, "filter_diverged", n_sats);
      } else {
        if (pending) count(sum.gnss_skipped, "filter_diverged", pending->n_sats);
        pending = PendingFix{(*in_.rover)[gi].time, *pa, n_sats};
      }
      ++gi;
    }
    if (!pending || !stance) return false;
    if (t - pending->t > kReinitMaxFixAgeS) {
      count(sum.gnss_skipped, "filter_diverged", pending->n_sats);
      pending.reset();
      return false;
    }
    count(sum.gnss_skipped, "reinitialization_epoch", pending->n_sats);
    ins::NavState nav = last_stance.nav;
    nav.t = t;
    nav.p_eb_e = pending->p_ea_e - lever_e(pending->p_ea_e);
    nav.v_eb_e.setZero();
    f.init(nav, last_stance.imu, std::max(o_.initial_sigma_yaw_rad, kReinitSigmaYawRad));
    f.set_block_sigma(ins::kVel, kReinitSigmaVelMps);
    f.set_block_sigma(ins::kPos, std::max(o_.initial_sigma_pos_m, kReinitSigmaPosM));
    ++sum.reinitializations;
    sum.health_events.push_back("re-initialized at " + t.to_string() + " from the GNSS epoch solution of " +
                                pending->t.to_string());
    pending.reset();
    return true;
  }

  // One output epoch from a nominal navigation state and the covariance of its error (forward or smoothed).
  EpochOutput output(const ins::InsState& x, const ErrorMatrix& P, GpsTime t, bool zupt, int used, int rejected) const {
    EpochOutput e;
    e.t = t;
    e.nav = x.nav;
    e.imu = x.imu;
    const ins::NavState& nav = x.nav;
    const Geodetic llh = geodetic_from_ecef(e.nav.p_eb_e);
    const Eigen::Matrix3d Rne = R_e_n(llh.lat, llh.lon).transpose();
    Eigen::Matrix3d cov_p_e = P.block<3, 3>(ins::kPos.offset, ins::kPos.offset);
    Eigen::Matrix3d cov_v_e = P.block<3, 3>(ins::kVel.offset, ins::kVel.offset);
    Eigen::Matrix3d cov_att_e = P.block<3, 3>(ins::kAtt.offset, ins::kAtt.offset);
    if (frame_.var_rad2 > 0.0) {
      // Rotation of the trajectory by δψ about the vertical through the start (docs/fusion.md eq. 5.10).
      const Vector3d s_p = frame_.up_e.cross(nav.p_eb_e - frame_.origin_e);
      const Vector3d s_v = frame_.up_e.cross(nav.v_eb_e);
      cov_p_e += frame_.var_rad2 * s_p * s_p.transpose();
      cov_v_e += frame_.var_rad2 * s_v * s_v.transpose();
      cov_att_e += frame_.var_rad2 * frame_.up_e * frame_.up_e.transpose();
    }
    e.cov_p_n = Rne * cov_p_e * Rne.transpose();
    e.cov_v_n = Rne * cov_v_e * Rne.transpose();
    const Eigen::Matrix3d att_n = Rne * cov_att_e * Rne.transpose();
    e.sd_yaw_rad = std::sqrt(std::max(0.0, att_n(2, 2)));
    e.n_sats_used = used;
    e.n_sats_rejected = rejected;
    e.zupt = zupt;
    return e;
  }

  // ZUPT: z = 0 - v_est; form D adds the attitude coupling [v×] (seed 001 eq. 8); ZARU: omega - b_g - omega_ie.
  // ZARU uses the mean (bias-corrected) rate over the interval, only when the whole interval is stance (its start
  // had a ZUPT too, so neither end is at a stance edge).
  void zupt_update(Filter& f, const ins::ImuIncrement& inc, bool interval_start_stance, EngineSummary& sum) {
    const int n = f.layout().dim();
    const Vector3d v = f.x().nav.v_eb_e;
    bool zaru = o_.zaru && interval_start_stance && inc.dt_s > 0.0;
    Vector3d r_zaru = Vector3d::Zero();
    Rows3 H_zaru;
    if (zaru) {
      H_zaru = zaru_rows(f, inc, r_zaru);
      if (zaru_gate_threshold_ > 0.0 && !zaru_passes_gate(f, H_zaru, r_zaru, zaru_variance(inc))) {
        zaru = false;
        ++sum.zaru_rejected;
      }
    }
    sum.zaru_updates += zaru;
    const int m = zaru ? 6 : 3;
    // Fixed capacity (6 rows): no heap allocation.
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, ins::kMaxErrorDim> H =
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, ins::kMaxErrorDim>::Zero(m, n);
    Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 6, 1> r(m);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6> R =
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6>::Zero(m, m);
    const Eigen::Matrix<double, 3, 6> J = zupt_jacobian(v, o_.zupt_form);
    H.block<3, 3>(0, ins::kVel.offset) = J.leftCols<3>();
    H.block<3, 3>(0, ins::kAtt.offset) = J.rightCols<3>();
    r.head<3>() = -v;
    R.topLeftCorner<3, 3>().diagonal().setConstant(o_.zupt_sigma_mps * o_.zupt_sigma_mps);
    if (zaru) {
      H.middleRows<3>(3) = H_zaru;
      r.tail<3>() = r_zaru;
      R.bottomRightCorner<3, 3>().diagonal().setConstant(zaru_variance(inc));
    }
    const Vector3d v_before = v;
    if (!f.update(r, H, R)) return;
    if (o_.zupt_form == ZuptForm::kDynamic) {
      // The error state is kept in the dynamic-error sense only through v̂; the update moved v̂, so re-express the
      // covariance at the new v̂: P <- J P J^T, J = I + E_v [(v̂- - v̂+)x] E_φ^T (docs/fusion.md eq. 5.9). Without it
      // the velocity-yaw correlation left by the swing makes the following stance ZUPTs act like form F.
      f.reexpress_velocity_attitude(skew(v_before - f.x().nav.v_eb_e));
    }
  }

  // Persistent-fault statistic of a code row with w-statistic `w` (docs/fusion.md eq. 6.5): the largest
  // (Σ w)² / n over the windows of n = 2..N consecutive epochs that end with this one, the earlier terms from the
  // satellite's history (each clipped to the single-epoch threshold k, so a blunder the single test already caught
  // cannot carry the next epochs). Only when |w| ≥ 1 and the window sum has the sign of w: the fault must show in this
  // epoch too. 0 when the test is off or the satellite has no history from the previous epoch.
  double persistent_fault_statistic(const gnss::SatId& sat, double w) const {
    if (o_.fault_window_epochs < 2 || std::abs(w) < 1.0) return 0.0;
    const auto it = find_fault_history(fault_history_, sat);
    if (it == fault_history_.end() || it->epoch != gnss_epoch_ - 1) return 0.0;
    const FaultHistory& h = *it;
    const double k = std::sqrt(w_test_threshold_);
    double sum_w = w, best = 0.0;
    for (int j = 0; j < h.count && j + 2 <= o_.fault_window_epochs; ++j) {
      sum_w += std::clamp(h.w[static_cast<size_t>(j)], -k, k);
      if (sum_w * w > 0.0) best = std::max(best, sum_w * sum_w / (j + 2));
    }
    return best;
  }

  // After the epoch's update: each code row's w in the last test it took part in becomes the newest history entry of
  // its satellite (a satellite missing from an epoch starts over).
  void record_fault_history(const std::vector<Row>& rows) {
    if (o_.fault_window_epochs >= 2) {
      for (size_t i = 0; i < rows.size(); ++i) {
        if (rows[i].doppler) continue;
        FaultHistory& h = fault_history_slot(rows[i].sat);
        if (h.epoch != gnss_epoch_ - 1) h.count = 0;
        const int keep = std::min(h.count, o_.fault_window_epochs - 2);
        for (int j = keep; j > 0; --j) h.w[static_cast<size_t>(j)] = h.w[static_cast<size_t>(j - 1)];
        h.w[0] = w_last_[i];
        h.count = keep + 1;
        h.epoch = gnss_epoch_;
      }
    }
    ++gnss_epoch_;
  }

  // The history entry of `sat`: its own, else a new one, else the one not updated for longest (a set satellite).
  FaultHistory& fault_history_slot(const gnss::SatId& sat) {
    auto it = find_fault_history(fault_history_, sat);
    if (it != fault_history_.end()) return *it;
    if (fault_history_.size() < static_cast<size_t>(kMaxGnssRows)) {
      fault_history_.push_back(FaultHistory{});
      it = fault_history_.end() - 1;
    } else {
      it = std::min_element(fault_history_.begin(), fault_history_.end(),
                            [](const FaultHistory& a, const FaultHistory& b) { return a.epoch < b.epoch; });
      *it = FaultHistory{};
    }
    it->sat = sat;
    return *it;
  }

  // ZARU rows: the measured rate (corrected by the current bias estimate) should equal the Earth rate in b; residual
  // into `r`, Jacobian returned (3 x n).
  Rows3 zaru_rows(const Filter& f, const ins::ImuIncrement& inc, Vector3d& r) const {
    Rows3 H = Rows3::Zero(3, f.layout().dim());
    const Vector3d omega_ie_b = f.x().nav.R_e_b().transpose() * Vector3d(0, 0, wgs84::kOmegaIE_radps);
    r = inc.alpha_b / inc.dt_s - omega_ie_b;  // = true - estimated bias if the foot is still
    H.block<3, 3>(0, ins::kBiasGyro.offset).setIdentity();
    // The g-sensitive part δG_g f of the corrected rate (docs/error_state.md eq. 5.4): without it the ZARU would
    // tell the bias apart from G_g f at rest, and the tilt drift the ZUPTs see would then "observe" G_g.
    if (const int g = f.g_sensitivity_offset(); g >= 0) {
      const Vector3d f_b = inc.upsilon_b / inc.dt_s;
      for (int j = 0; j < 3; ++j) H.block<3, 3>(0, g + 3 * j).diagonal().setConstant(f_b(j));
    }
    return H;
  }

  double zaru_variance(const ins::ImuIncrement& inc) const {
    return o_.zaru_sigma_radps * o_.zaru_sigma_radps / std::max(1, inc.samples);
  }

  // ZARU innovation gate (docs/fusion.md §5.3): d² = rᵀ S⁻¹ r, S = H P Hᵀ + R, against χ²(3) at zaru_gate_probability.
  bool zaru_passes_gate(const Filter& f, const Rows3& H, const Vector3d& r, double variance) const {
    Eigen::Matrix3d S = H * f.P() * H.transpose();
    S.diagonal().array() += variance;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(S);
    if (ldlt.info() != Eigen::Success) return false;
    const double d2 = r.dot(ldlt.solve(r));
    return std::isfinite(d2) && d2 <= zaru_gate_threshold_;
  }

  // Step-averaged velocity (seed 000 eq. 3): along/cross-track/vertical average velocity of the step vs ΔL/T, applied at the
  // stance onset that ends the step; state blocks: velocity and attitude (fusion/step_velocity.hpp).
  void step_velocity_update(Filter& f, const StepMeasurement& m, EngineSummary& sum) {
    const StepVelocityRows rows = step_velocity_rows(f.x().nav, m, o_.step_velocity);
    Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, ins::kMaxErrorDim> H =
        Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, ins::kMaxErrorDim>::Zero(3, f.layout().dim());
    H.block<3, 3>(0, ins::kVel.offset) = rows.J_dv_phi.leftCols<3>();
    H.block<3, 3>(0, ins::kAtt.offset) = rows.J_dv_phi.rightCols<3>();
    if (f.update(rows.residual, H, rows.cov_meas)) ++sum.step_velocity_updates;
  }

  // ++m[key] without constructing a std::string for keys already present (no heap allocation per epoch).
  static void count(std::map<std::string, long>& m, const char* key, size_t n = 1) {
    for (auto& [k, v] : m) {
      if (k == key) {
        v += static_cast<long>(n);
        return;
      }
    }
    m[key] += static_cast<long>(n);
  }

  // SD (or UD) pseudorange + Doppler update at rover epoch gi, processed at mechanization epoch t_proc >= epoch.
  void gnss_update(Filter& f, size_t gi, GpsTime t_proc, bool& clock_initialized, EngineSummary& sum, int& used_out,
                   int& rejected_out, std::vector<GnssRowRecord>* records) {
    re_ = (*in_.rover)[gi];  // copy into a reused buffer (no allocation once its capacity suffices)
    gnss::ObsEpoch& re = re_;
    if (in_.gnss_mask) {
      const size_t before = re.sats.size();
      in_.gnss_mask(re);
      if (before > re.sats.size()) count(sum.gnss_skipped, "masked", before - re.sats.size());
      if (re.sats.empty() && before > 0) {
        ++sum.gnss_epochs_masked;
        return;
      }
    }
    const gnss::ObsEpoch* be = nullptr;
    std::optional<gnss::ObsEpoch> propagated;
    // No base epoch within max_base_age_s (a base that stopped): the epoch is processed undifferenced. The clock states
    // change meaning (rover-base vs rover clock), so they are re-initialized at every switch (docs/robustness.md).
    const bool sd = sd_ && matches_[gi].base_index >= 0;
    if (sd_ && !sd) ++sum.gnss_epochs_undifferenced_no_base;
    if (last_sd_ && *last_sd_ != sd) clock_initialized = false;
    last_sd_ = sd;
    if (sd) {
      be = &(*in_.base)[matches_[gi].base_index];
      // An older (or later) base epoch is moved to the rover epoch with its own Doppler: the base clock drift is in
      // the Doppler, so the differential clock stays continuous across base epochs (docs/fusion.md §3).
      if (std::abs(re.time - be->time) > 1e-3) {
        propagated = gnss::propagate_base_with_doppler(*be, re.time);
        be = &*propagated;
      }
    }
    const int n = f.layout().dim();
    const double lag_s = t_proc - re.time;  // the state is at t_proc; move the antenna back to the epoch
    const Vector3d p_imu = f.x().nav.p_eb_e - f.x().nav.v_eb_e * lag_s;
    // Eq. 14.1: the level-frame arm plus the part fixed in the foot's heading frame, whose heading error enters the
    // code rows through eq. 14.2 (the arm's rotation rate is left out of the Doppler rows: 0.1 m × the foot's yaw
    // rate, inside the stride-velocity σ).
    const Geodetic llh_imu = geodetic_from_ecef(p_imu);
    const LeverArm arm = lever_arm_e(o_.lever_arm_n_m, o_.lever_arm_heading_m, R_e_n(llh_imu.lat, llh_imu.lon),
                                     f.x().nav.R_e_b());
    const Vector3d p_a = p_imu + arm.arm_e;
    // Antenna (body) velocity: the foot's stride-average velocity (eq. 13.1) or, with the kFoot model or before a
    // cycle of history exists, the foot's own velocity.
    std::optional<Vector3d> v_stride;
    if (o_.antenna_velocity_model == AntennaVelocityModel::kStrideAverage) v_stride = stride_.velocity_e();
    const Vector3d v_a = v_stride ? *v_stride : f.x().nav.v_eb_e;
    const Geodetic llh = geodetic_from_ecef(p_a);
    std::vector<Row>& rows = rows_;
    rows.clear();
    std::vector<std::vector<double>>& code_res_by_slot = code_res_by_slot_;
    code_res_by_slot.resize(o_.systems.size());
    for (auto& v : code_res_by_slot) v.clear();
    for (const gnss::SatObs& so : re.sats) {
      const int slot = system_slot(o_.systems, so.sat.system);
      if (slot < 0) {
        count(sum.gnss_skipped, "system_not_configured");
        continue;
      }
      if (std::isnan(so.pseudorange_m)) { count(sum.code_used_rejected, "no_pseudorange"); continue; }
      if (!std::isnan(so.cn0_dbhz) && so.cn0_dbhz < o_.min_cn0_dbhz) { count(sum.code_used_rejected, "low_cn0"); continue; }
      gnss::SignalAtReceiver rs, bs;
      rs.pseudorange_m = so.pseudorange_m;
      rs.range_rate_mps = -so.wavelength_m * so.doppler_hz;
      auto sr = gnss::satellite_state_at_reception(*in_.nav, so.sat, re.time, so.pseudorange_m);
      if (!sr) { count(sum.code_used_rejected, "no_ephemeris"); continue; }
      rs.sat = *sr;
      const gnss::ElevationAzimuth ea = gnss::elevation_azimuth(p_a, sr->p_es_e);
      if (ea.elevation < o_.elevation_mask_rad) { count(sum.code_used_rejected, "below_elevation_mask"); continue; }
      double cn0_b = so.cn0_dbhz;
      gnss::MeasurementRow code, rate;
      double sigma_c = gnss::measurement_sigma(o_.weights, so.cn0_dbhz, ea.elevation, false);
      double sigma_d = gnss::measurement_sigma(o_.weights, so.cn0_dbhz, ea.elevation, true);
      if (so.sat.system == gnss::System::kGlonass) sigma_c *= o_.weights.glonass_code_factor;
      bool have_rate = o_.use_doppler && std::isfinite(rs.range_rate_mps);
      if (sd) {
        auto it = std::find_if(be->sats.begin(), be->sats.end(), [&](const gnss::SatObs& b) { return b.sat == so.sat; });
        if (it == be->sats.end() || std::isnan(it->pseudorange_m)) { count(sum.code_used_rejected, "not_at_base"); continue; }
        auto sb = gnss::satellite_state_at_reception(*in_.nav, so.sat, be->time, it->pseudorange_m);
        if (!sb) { count(sum.code_used_rejected, "no_ephemeris"); continue; }
        bs.pseudorange_m = it->pseudorange_m;
        bs.range_rate_mps = -it->wavelength_m * it->doppler_hz;
        bs.sat = *sb;
        cn0_b = it->cn0_dbhz;
        const double el_b = gnss::elevation_azimuth(*o_.base_position_e, sb->p_es_e).elevation;
        const double sb_c = gnss::measurement_sigma(o_.weights, cn0_b, el_b, false) *
                            (so.sat.system == gnss::System::kGlonass ? o_.weights.glonass_code_factor : 1.0);
        sigma_c = std::hypot(sigma_c, sb_c);
        sigma_d = std::hypot(sigma_d, gnss::measurement_sigma(o_.weights, cn0_b, el_b, true));
        code = gnss::sd_pseudorange(so.sat, rs, bs, p_a, *o_.base_position_e, f.clock(slot));
        have_rate = have_rate && std::isfinite(bs.range_rate_mps);
        if (have_rate) rate = gnss::sd_range_rate(so.sat, rs, bs, p_a, v_a, *o_.base_position_e, f.drift());
      } else {
        const double iono = in_.nav->has_klobuchar ? gnss::klobuchar_delay_m(in_.nav->klobuchar, re.time, llh, ea) : 0.0;
        const double tropo = gnss::saastamoinen_delay_m(llh, ea.elevation);
        code = gnss::ud_pseudorange(so.sat, rs, p_a, f.clock(slot), iono, tropo);
        if (have_rate) rate = gnss::ud_range_rate(so.sat, rs, p_a, v_a, f.drift());
      }
      Row rc;
      rc.sat = so.sat;
      rc.residual = code.residual;
      rc.sigma = sigma_c;
      rc.h = ins::ErrorRowVector::Zero(n);
      rc.h.segment<3>(ins::kPos.offset) = code.J_p;
      rc.h.segment<3>(ins::kAtt.offset) = code.J_p * arm.d_arm_d_phi_e;  // eq. 14.2 (zero without a heading part)
      rc.j_antenna = code.J_p;
      rc.h(f.clock_offset(slot)) = code.J_clock;
      if (f.has_multipath()) {
        // Code multipath σ_mp(C/N0) u_s (docs/consistency.md eq. M.2); SD: rover and base in quadrature.
        auto mp_sigma = [&](double cn0) {
          const double c = std::isnan(cn0) ? o_.multipath_cn0_ref_dbhz : cn0;
          return o_.multipath_sigma_m * std::pow(10.0, std::max(0.0, o_.multipath_cn0_ref_dbhz - c) / 20.0);
        };
        const double s_mp = sd ? std::hypot(mp_sigma(so.cn0_dbhz), mp_sigma(cn0_b)) : mp_sigma(so.cn0_dbhz);
        bool reset = false;
        const int ms = f.multipath_slot(so.sat, re.time.ns(), reset);
        if (reset) ++sum.multipath_resets;
        if (ms >= 0) {
          rc.h(f.multipath_index(ms)) = s_mp;
          rc.residual -= s_mp * f.multipath_value(ms);
        } else {
          rc.sigma = std::hypot(rc.sigma, s_mp);
        }
      }
      code_res_by_slot[slot].push_back(rc.residual);
      rows.push_back(rc);
      if (have_rate) {
        Row rd;
        rd.sat = so.sat;
        rd.doppler = true;
        rd.residual = rate.residual;
        rd.sigma = sigma_d;
        rd.h = ins::ErrorRowVector::Zero(n);
        rd.h.segment<3>(ins::kPos.offset) = rate.J_p;
        rd.j_antenna = rate.J_v;
        if (v_stride) {
          // δv̄ = −[v̄×] φ (eq. 13.2): the heading error rotates the INS stride; the velocity error is not in v̄.
          rd.h.segment<3>(ins::kAtt.offset) = rate.J_v * stride_velocity_attitude_jacobian(*v_stride);
        } else {
          rd.h.segment<3>(ins::kVel.offset) = rate.J_v;
        }
        rd.h(f.drift_offset()) = rate.J_drift;
        rows.push_back(rd);
      }
    }
    if (rows.empty()) return;
    // Clock initialization / jump detection from the median code innovation per constellation.
    bool any_reset = false;
    for (size_t s = 0; s < o_.systems.size(); ++s) {
      if (code_res_by_slot[s].empty()) continue;
      const double med = median(code_res_by_slot[s]);
      const double sd = std::sqrt(f.P()(f.clock_offset(static_cast<int>(s)), f.clock_offset(static_cast<int>(s))));
      if (!clock_initialized || (std::abs(med) > o_.clock_jump_threshold_m && std::abs(med) > 5.0 * sd)) {
        if (clock_initialized) ++sum.clock_resets;
        f.reset_clock(static_cast<int>(s), f.clock(static_cast<int>(s)) + med, 30.0);
        for (Row& r : rows) {
          if (!r.doppler && system_slot(o_.systems, r.sat.system) == static_cast<int>(s)) r.residual -= med;
        }
        any_reset = true;
      }
    }
    if (!clock_initialized) {
      std::vector<double>& d = doppler_res_;
      d.clear();
      for (const Row& r : rows) if (r.doppler) d.push_back(r.residual);
      if (!d.empty()) {
        const double med = median(d);
        f.reset_drift(f.drift() + med, 1.0);
        for (Row& r : rows) if (r.doppler) r.residual -= med;
      }
      clock_initialized = true;
    }
    (void)any_reset;
    // Noise: independent per measurement + the non-rigid antenna offset/velocity common to all satellites.
    const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
    const Eigen::Matrix3d C_pos = Ren * Vector3d(o_.antenna_sigma_horizontal_m * o_.antenna_sigma_horizontal_m,
                                                 o_.antenna_sigma_horizontal_m * o_.antenna_sigma_horizontal_m,
                                                 o_.antenna_sigma_vertical_m * o_.antenna_sigma_vertical_m)
                                            .asDiagonal() * Ren.transpose();
    const double svh = v_stride ? o_.antenna_stride_velocity_sigma_horizontal_mps : o_.antenna_velocity_sigma_horizontal_mps;
    const double svv = v_stride ? o_.antenna_stride_velocity_sigma_vertical_mps : o_.antenna_velocity_sigma_vertical_mps;
    const Eigen::Matrix3d C_vel = Ren * Vector3d(svh * svh, svh * svh, svv * svv).asDiagonal() * Ren.transpose();
    // w-test fault rejection, worst first (Baarda): w_i = (S^-1 nu)_i / sqrt((S^-1)_ii) against chi2(1, p).
    const double threshold = w_test_threshold_;
    std::vector<int>& active = active_;
    active.resize(rows.size());
    for (size_t i = 0; i < rows.size(); ++i) active[i] = static_cast<int>(i);
    w_last_.assign(rows.size(), 0.0);
    int rejected_code = 0;
    // Up to kMaxGnssRows rows in fixed-capacity matrices (no heap allocation), more in dynamic ones.
    auto build = [&](auto& H, auto& r, auto& R) {
      const int m = static_cast<int>(active.size());
      H.resize(m, n);
      r.resize(m);
      R.setZero(m, m);
      for (int i = 0; i < m; ++i) {
        const Row& a = rows[active[i]];
        H.row(i) = a.h;
        r(i) = a.residual;
        R(i, i) = a.sigma * a.sigma;
      }
      for (int i = 0; i < m; ++i) {
        for (int j = 0; j < m; ++j) {
          const Row& a = rows[active[i]];
          const Row& b = rows[active[j]];
          if (a.doppler == b.doppler) R(i, j) += a.j_antenna * (a.doppler ? C_vel : C_pos) * b.j_antenna.transpose();
        }
      }
    };
    const size_t first_record = records ? records->size() : 0;
    bool first_test = true;
    auto solve = [&](auto& H, auto& r, auto& R) {
    using SMatrix = std::remove_reference_t<decltype(R)>;
    using RVector = std::remove_reference_t<decltype(r)>;
    for (;;) {
      build(H, r, R);
      SMatrix S = R;
      S.noalias() += H * f.P() * H.transpose();
      const SMatrix Sinv = S.ldlt().solve(SMatrix::Identity(S.rows(), S.cols()));
      const RVector a = Sinv * r;
      if (records && first_test) {
        // Baarda's internal reliability: MDB_i = (k + z_0.8) / sqrt((S^-1)_ii), k = sqrt(threshold) (docs/fusion.md eq. 6.4).
        constexpr double kZPower80 = 0.8416;
        const double sqrt_lambda = std::sqrt(threshold) + kZPower80;
        for (int i = 0; i < a.size(); ++i) {
          const Row& row = rows[active[i]];
          GnssRowRecord rec;
          rec.t = re.time;
          rec.sat = row.sat;
          rec.doppler = row.doppler;
          rec.innovation = row.residual;
          rec.sigma = row.sigma;
          rec.w = a(i) / std::sqrt(Sinv(i, i));
          rec.mdb = sqrt_lambda / std::sqrt(Sinv(i, i));
          records->push_back(rec);
        }
      }
      first_test = false;
      int worst = -1;
      double worst_w2 = threshold;
      bool worst_persistent = false;
      for (int i = 0; i < a.size(); ++i) {
        const double w = a(i) / std::sqrt(Sinv(i, i));
        w_last_[static_cast<size_t>(active[i])] = w;
        if (records) (*records)[first_record + static_cast<size_t>(active[i])].w_final = w;
        const double w2 = w * w;
        if (w2 > worst_w2) {
          worst_w2 = w2;
          worst = i;
          worst_persistent = false;
        }
        if (const Row& row = rows[active[i]]; !row.doppler) {
          const double g2 = persistent_fault_statistic(row.sat, w);
          if (g2 > worst_w2) {
            worst_w2 = g2;
            worst = i;
            worst_persistent = true;
          }
        }
      }
      if (worst < 0 || active.size() <= 1) break;
      const Row& bad = rows[active[worst]];
      if (records) (*records)[first_record + static_cast<size_t>(active[worst])].rejected = true;
      if (bad.doppler) {
        count(sum.doppler_used_rejected, "innovation_fault");
      } else {
        count(sum.code_used_rejected, worst_persistent ? "persistent_fault" : "innovation_fault");
        ++rejected_code;
      }
      active.erase(active.begin() + worst);
    }
    };
    bool updated = false;
    if (static_cast<int>(rows.size()) <= kMaxGnssRows) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxGnssRows, ins::kMaxErrorDim> H;
      Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxGnssRows, 1> r;
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxGnssRows, kMaxGnssRows> R;
      solve(H, r, R);
      updated = f.update(r, H, R);
    } else {
      MatrixXd H, R;
      VectorXd r;
      solve(H, r, R);
      updated = f.update(r, H, R);
    }
    if (updated) ++sum.gnss_epochs_used;
    record_fault_history(rows);
    // Divergence watch: most code rows of a well-observed epoch rejected, epoch after epoch (kImplausibleEpochs).
    const int code_rows = static_cast<int>(std::count_if(rows.begin(), rows.end(), [](const Row& w) { return !w.doppler; }));
    if (code_rows >= kImplausibleMinCodeRows && 2 * rejected_code > code_rows) ++implausible_streak_;
    else implausible_streak_ = 0;
    const char* outcome = updated ? "used" : "update_failed";
    int used_code = 0;
    for (int i : active) {
      if (rows[i].doppler) count(sum.doppler_used_rejected, outcome);
      else { count(sum.code_used_rejected, outcome); used_code += updated; }
    }
    used_out = used_code;
    rejected_out = rejected_code;
  }

 private:
  const EngineInputs& in_;
  const EngineOptions& o_;
  const std::vector<ins::ZuptDecision>& decisions_;
  std::vector<bool> zupt_ok_;  // stance samples a ZUPT/ZARU may use (zupt_edge_s trimmed; ins::zupt_update_samples)
  const double w_test_threshold_;  // chi2(1) quantile at o_.fault_probability
  const double zaru_gate_threshold_;  // chi2(3) quantile at o_.zaru_gate_probability; 0 = no gate
  ins::SaturationRepair saturation_;  // clipped samples repaired once per run (docs/ins.md §9)
  StrideVelocity stride_;             // stride-average foot velocity: the antenna velocity (docs/fusion.md §13)
  std::vector<gnss::BaseMatch> matches_;
  bool sd_ = false;
  FrameYaw frame_;
  std::optional<bool> last_sd_;  // differencing of the last processed GNSS epoch (SD or undifferenced)
  int implausible_streak_ = 0;   // consecutive GNSS epochs with most code rows rejected
  // Per-epoch buffers, reused (their capacity persists: no heap allocation after the first epochs).
  gnss::ObsEpoch re_;
  std::vector<Row> rows_;
  std::vector<std::vector<double>> code_res_by_slot_;
  std::vector<double> doppler_res_;
  std::vector<int> active_;
  std::vector<double> w_last_;  // per row of the epoch: w in the last test it took part in
  // Persistent-fault test (docs/fusion.md §6.2): per satellite, the code w of the last consecutive GNSS epochs.
  std::vector<FaultHistory> fault_history_;  // at most kMaxGnssRows satellites, reserved once (no allocation per epoch)
  long gnss_epoch_ = 0;  // GNSS epochs that reached the w-test
};

// 2D rigid fit (rotation about the vertical + translation) of src onto dst (ENU); returns the rotation angle
// (counter-clockwise, rad) and the RMS of the residuals [m].
// printf-style message (the engine's texts; fusion/ has no logging or fmt dependency).
template <typename... Args>
std::string fmt_message(const char* format, Args... args) {
  char buf[400];
  std::snprintf(buf, sizeof buf, format, args...);
  return buf;
}

std::pair<double, double> fit_yaw(const std::vector<Vector3d>& src, const std::vector<Vector3d>& dst) {
  Vector3d ms = Vector3d::Zero(), md = Vector3d::Zero();
  for (size_t i = 0; i < src.size(); ++i) ms += src[i], md += dst[i];
  ms /= static_cast<double>(src.size());
  md /= static_cast<double>(src.size());
  double sxx = 0, sxy = 0;
  for (size_t i = 0; i < src.size(); ++i) {
    const Vector3d a = src[i] - ms, b = dst[i] - md;
    sxx += a.x() * b.x() + a.y() * b.y();
    sxy += a.x() * b.y() - a.y() * b.x();
  }
  const double th = std::atan2(sxy, sxx);
  const double c = std::cos(th), s = std::sin(th);
  double ss = 0;
  for (size_t i = 0; i < src.size(); ++i) {
    const Vector3d a = src[i] - ms, b = dst[i] - md;
    const double ex = c * a.x() - s * a.y() - b.x(), ey = s * a.x() + c * a.y() - b.y();
    ss += ex * ex + ey * ey;
  }
  return {th, std::sqrt(ss / static_cast<double>(src.size()))};
}

}  // namespace

Eigen::Matrix<double, 3, 6> zupt_jacobian(const Eigen::Vector3d& v_e, ZuptForm form) {
  // Error state: v_true = v_est + δv, R_true = exp([φ×]) R_est (docs/error_state.md). The velocity error that an
  // attitude error alone produces is φ × v̂ = -[v̂×]φ; the dynamic error (seed 001 eq. 5) is δv_dyn = δv + [v̂×]φ,
  // and form D measures it (seed 001 eq. 8): H = [I, [v̂×]]. Form F measures δv itself: H = [I, 0].
  Eigen::Matrix<double, 3, 6> J = Eigen::Matrix<double, 3, 6>::Zero();
  J.leftCols<3>().setIdentity();
  if (form == ZuptForm::kDynamic) J.rightCols<3>() = skew(v_e);
  return J;
}

std::vector<std::string> EngineOptions::problems() const {
  std::vector<std::string> p = zupt.problems();
  if (!(mechanization_rate_hz > 0)) p.push_back("mechanization_rate_hz must be > 0");
  if (!(output_rate_hz > 0)) p.push_back("output.rate_hz must be > 0");
  if (!(zupt_sigma_mps > 0)) p.push_back("zupt.sigma_mps must be > 0");
  if (!(fault_probability > 0.5 && fault_probability < 1.0)) p.push_back("fault_rejection.probability must be in (0.5, 1)");
  if (fault_window_epochs < 0 || fault_window_epochs > kMaxFaultWindowEpochs)
    p.push_back("fault_rejection.window_epochs must be in [0, " + std::to_string(kMaxFaultWindowEpochs) + "]");
  if (!(zaru_gate_probability == 0.0 || (zaru_gate_probability > 0.5 && zaru_gate_probability < 1.0)))
    p.push_back("zupt.zaru_gate_probability must be 0 (no gate) or in (0.5, 1)");
  for (const auto& s : spec.problems()) p.push_back("imu.spec: " + s);

  return p;
}

Expected<EngineResult> run_forward(const EngineInputs& in, const EngineOptions& o) {
  if (auto p = o.problems(); !p.empty()) {
    std::string s;
    for (const auto& x : p) s += (s.empty() ? "" : "; ") + x;
    return make_error("engine options: " + s);
  }
  if (!in.imu || in.imu->size() < 10) return make_error("IMU: fewer than 10 samples");
  const auto& samples = *in.imu;
  const bool tc = o.mode == Mode::kTightlyCoupled;
  if (tc) {
    if (!in.nav || !in.rover || in.rover->empty()) return make_error("tc mode needs rover observations and nav data");
    const GpsTime g0 = in.rover->front().time, g1 = in.rover->back().time;
    if (g1 < samples.front().t || g0 > samples.back().t) {
      return make_error("GNSS (" + g0.to_string() + " .. " + g1.to_string() + ") and IMU (" +
                        samples.front().t.to_string() + " .. " + samples.back().t.to_string() +
                        ") time spans do not overlap");
    }
    if (in.base && !o.base_position_e) return make_error("base observations given without a base position");
  }
  if (auto p = ins::stance_label_problem(o.zupt, in.stance_labels, samples.size()); !p.empty()) return make_error(p);
  const std::vector<ins::ZuptDecision> decisions = ins::detect_stance(samples, o.zupt, in.stance_labels);

  // Start at the first still period (levelling window): the first stance run of >= 0.2 s.
  size_t s0 = 0, s1 = 0;
  for (size_t i = 0; i < decisions.size(); ++i) {
    if (!decisions[i].stance) continue;
    size_t j = i;
    while (j + 1 < decisions.size() && decisions[j + 1].stance) ++j;
    if (samples[j].t - samples[i].t >= 0.2) {
      s0 = i;
      s1 = j + 1;
      break;
    }
    i = j;
  }
  if (s1 == 0) return make_error("IMU: no still period found to level the IMU (the ZUPT detector never fired)");
  const std::vector<ins::ImuSample> still(samples.begin() + static_cast<long>(s0), samples.begin() + static_cast<long>(s1));

  EngineResult result;
  EngineSummary& sum = result.summary;
  for (const auto& d : decisions) sum.zupt_samples += d.stance;
  if (in.rover) sum.gnss_epochs = static_cast<long>(in.rover->size());
  if (in.rover && tc) {
    for (const auto& e : *in.rover) sum.gnss_measurements += static_cast<long>(e.sats.size());
  }
  Runner runner(in, o, decisions);

  // Initial position: configured, else the first epoch LSQ solution after the start (antenna -> IMU).
  Vector3d p0;
  std::string how;
  if (o.initial_position_e) {
    p0 = *o.initial_position_e;
    how = "position from configuration";
  } else if (tc) {
    std::optional<Vector3d> pa;
    for (size_t g = 0; g < in.rover->size() && !pa; ++g) {
      if ((*in.rover)[g].time < samples[s0].t) continue;
      pa = runner.lsq_position(g, o.base_position_e.value_or(Vector3d::Zero()));
      if (pa) how = "position from the GNSS epoch solution at " + (*in.rover)[g].time.to_string();
    }
    if (!pa) return make_error("no GNSS epoch after the IMU start could be solved to initialize the position");
    p0 = *pa - runner.lever_e(*pa);
  } else {
    return make_error("mode ins needs an initial position (initial.position_ecef_m or initial.lat_deg/lon_deg/h_m)");
  }
  auto level = ins::coarse_level(still, p0, 0.0, ins::StillnessOptions{1.0, 2.0, 2.0, 0.1});
  if (!level) return make_error("IMU levelling at " + samples[s0].t.to_string() + ": " + level.error().message);
  ins::ImuErrors imu0;
  // The still period's mean rate as the initial gyro bias — unless the window moved (docs/ins.md §6, eq. 6.1).
  if (level->duration_s >= 2.0) {
    const Vector3d b_deg_per_h = level->gyro_bias_b * kRadToDeg * 3600.0;
    // A spec without a turn-on σ has no prior to check against: the window's mean is taken (d² stays 0).
    if (o.spec.gyro_bias_initial > 0.0)
      sum.still_gyro_bias_d2 = ins::still_gyro_bias_d2(*level, o.spec.gyro_bias_initial, o.spec.gyro_arw);
    if (sum.still_gyro_bias_d2 <= gnss::chi_square_quantile(kStillGyroBiasGateProbability, 3)) {
      imu0.b_g = level->gyro_bias_b;
      sum.initial_gyro_bias_deg_per_h = b_deg_per_h;
    } else {
      how += fmt_message("; gyro bias not taken from the first still period (mean rate %.0f, %.0f, %.0f deg/h is %.1f "
                         "turn-on sigmas: the IMU moved)",
                         b_deg_per_h.x(), b_deg_per_h.y(), b_deg_per_h.z(), std::sqrt(sum.still_gyro_bias_d2));
    }
  }

  // Heading: configured, else from motion (INS/ZUPT track with yaw 0 fitted to the GNSS epoch solutions).
  double yaw0 = 0.0;
  EngineOptions opt = o;
  if (o.initial_yaw_rad) {
    yaw0 = *o.initial_yaw_rad;
    how += "; heading from configuration";
  } else if (tc) {
    // Pass 1 (docs/fusion.md §8): the INS/ZUPT track with yaw 0, and at each milestone D, 2D, 4D, … of distance
    // walked (which does not depend on the heading; a GNSS track can "move" D while the person stands, by noise and
    // blunders) a 2D fit of that track onto the GNSS epoch solutions over the same span. The pass stops at the first
    // fit with σ_yaw <= kHeadingInitTargetSigma on a track >= 10 m from its start, or after kHeadingInitDoublings
    // further milestones.
    constexpr double kHeadingInitTargetSigma = 3.0 * kDegToRad;
    constexpr int kHeadingInitDoublings = 5;  // up to 32 D
    EngineOptions ins_only = o;
    ins_only.mode = Mode::kInsOnly;
    ins_only.initial_sigma_yaw_rad = 1e-3;
    ins_only.smoother_enabled = false;
    ins_only.output_rate_hz = o.mechanization_rate_hz;  // the INS antenna track at the GNSS epochs, sampled at 20 Hz
    std::vector<std::pair<GpsTime, Vector3d>> lsq;        // GNSS epoch solutions from the start, in time order
    size_t next_g = 0;
    Vector3d prev = p0;
    Vector3d first = Vector3d::Zero();
    double distance_m = 0.0, theta = 0.0, rms = 0.0, sigma_yaw = 0.0, extent_m = 0.0;
    size_t n_fit = 0;
    int fits = 0;
    GpsTime stop;
    // The fit over the pass-1 outputs so far; false if the track is too short to fit (extent < 10 m or < 5 points).
    auto fit_so_far = [&](const EngineResult& pass1) {
      stop = pass1.epochs.back().t;
      // Largest horizontal distance of the track from its start (the fit needs extent; a loop returns near its start).
      const Vector3d p_beg = pass1.epochs.front().nav.p_eb_e, up = p_beg.normalized();
      extent_m = 0.0;
      for (const auto& e : pass1.epochs) {
        const Vector3d d = e.nav.p_eb_e - p_beg;
        extent_m = std::max(extent_m, (d - d.dot(up) * up).norm());
      }
      for (; next_g < in.rover->size() && (*in.rover)[next_g].time <= stop; ++next_g) {
        if ((*in.rover)[next_g].time < samples[s0].t) continue;
        auto pa = runner.lsq_position(next_g, prev);
        if (!pa) continue;
        prev = *pa;
        if (lsq.empty()) first = *pa;
        lsq.push_back({(*in.rover)[next_g].time, *pa});
      }
      std::vector<Vector3d> src, dst;
      size_t k = 0;
      for (const auto& [t, pa] : lsq) {
        while (k + 1 < pass1.epochs.size() && pass1.epochs[k + 1].t <= t) ++k;
        if (k >= pass1.epochs.size() || std::abs(pass1.epochs[k].t - t) > 0.06) continue;
        const Vector3d p_imu = pass1.epochs[k].nav.p_eb_e;
        src.push_back(enu_from_ecef(p_imu + runner.lever_e(p_imu), first));
        dst.push_back(enu_from_ecef(pa, first));
      }
      if (src.size() < 5 || extent_m < 10.0) return false;
      std::tie(theta, rms) = fit_yaw(src, dst);
      double spread2 = 0;
      Vector3d mean = Vector3d::Zero();
      for (const auto& p : src) mean += p;
      mean /= static_cast<double>(src.size());
      for (const auto& p : src) spread2 += (p - mean).head<2>().squaredNorm();
      sigma_yaw = std::clamp(2.0 * rms / std::sqrt(std::max(spread2, 1.0)), 1.0 * kDegToRad, 30.0 * kDegToRad);
      n_fit = src.size();
      return true;
    };
    // One pass: at every milestone D, 2D, 4D, … fit what has been walked; stop at a fit with σ_yaw <= target, or at
    // the last milestone. No milestone reached (the data end first): fit whatever was walked.
    bool fitted = false;
    PassOptions p1;
    p1.gnss = false;
    p1.walked_milestone_m = o.heading_init_distance_m;
    p1.at_milestone = [&](const EngineResult& so_far, double milestone_m) {
      if (so_far.epochs.empty()) return false;
      distance_m = milestone_m;
      ++fits;
      fitted = fit_so_far(so_far);
      return (fitted && sigma_yaw <= kHeadingInitTargetSigma) || fits > kHeadingInitDoublings;
    };
    EngineResult pass1;
    Runner r1(in, ins_only, decisions);
    if (auto ok = r1.run(s0, ins::nav_state_at_rest(samples[s0].t, p0, level->roll, level->pitch, 0.0), imu0, p1, pass1);
        !ok) {
      return make_error("heading initialization pass: " + ok.error().message);
    }
    if (pass1.epochs.empty()) return make_error("heading initialization pass: no output epoch");
    if (pass1.epochs.back().t > stop) {  // the data ended before the last milestone: fit the whole pass
      distance_m = std::max(distance_m, o.heading_init_distance_m);
      fitted = fit_so_far(pass1);
    }
    if (!fitted) {
      return make_error(fmt_message("cannot find the initial heading from motion: the INS/ZUPT track goes %.1f m from its start "
                                    "(at least 10 m with 5 GNSS epoch solutions needed); set initial.yaw_deg",
                                    extent_m));
    }
    yaw0 = wrap_pi(-theta);  // ENU rotation counter-clockwise by theta = heading change of -theta
    opt.initial_sigma_yaw_rad = sigma_yaw;
    sum.heading_fit_rms_m = rms;
    sum.heading_init_end = stop;
    sum.heading_init_distance_m = distance_m;
    how += fmt_message("; heading from motion: INS/ZUPT track (%.0f m walked) fitted to %zu GNSS epoch solutions until "
                       "%s (fit RMS %.2f m, yaw sigma %.1f deg)",
                       distance_m, n_fit, stop.to_string().c_str(), rms, sigma_yaw * kRadToDeg);
  } else {
    return make_error("mode ins needs an initial heading (initial.yaw_deg)");
  }
  sum.initial_yaw_deg = yaw0 * kRadToDeg;
  sum.initialization = how;
  Runner runner2(in, opt, decisions);
  PassOptions po;
  po.gnss = tc;
  const ins::NavState nav0 = ins::nav_state_at_rest(samples[s0].t, p0, level->roll, level->pitch, yaw0);
  if (auto ok = runner2.run(s0, nav0, imu0, po, result); !ok) return ok.error();
  sum.imu_samples_used = sum.imu_samples;
  if (s0 > 0) sum.imu_skipped["before_first_still_period"] += static_cast<long>(s0);
  sum.imu_samples += static_cast<long>(s0);  // samples before the start were used for levelling only
  return result;
}

}  // namespace pednav::fusion
