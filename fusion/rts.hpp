// SPDX-License-Identifier: BSD-2-Clause
// Rauch-Tung-Striebel smoothing of a closed-loop (feedback) error-state filter, as pure linear algebra: no INS,
// no I/O. Between two output epochs a < b the forward filter feeds its own events (prediction, updates with their
// gains, re-expressions, state resets) into RtsInterval, which carries the cross-covariance of the error at a with
// the current error and closes the interval at b into one record per output epoch (docs/fusion.md §12 "Smoother",
// eqs. 12.14-12.20); rts_backward runs the records backwards (eq. 12.10). The per-step backward maps (rts_step,
// RtsAccumulator, eqs. 12.1-12.13) are the earlier formulation of the same records, kept as the reference the tests
// compare against. Memory and speed: docs/performance.md. Working matrices have a fixed capacity (ins::ErrorMatrix):
// no heap allocation per step; the stored records are packed doubles in one growing array.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <vector>

#include "core/row_transition.hpp"
#include "ins/error_state.hpp"

namespace pednav::fusion {

using ins::ErrorMatrix;
using ins::ErrorVector;

/// Backward map of one step j -> j+1 (docs/fusion.md eq. 12.7): ŝ_j = G ŝ_{j+1} + g,  P_s,j = Σ + G P_s,{j+1} Gᵀ.
/// Reference formulation (tests, benchmarks); the engine builds its records with RtsInterval.
struct RtsStep {
  ErrorMatrix G;      ///< C_j A_{j+1}  (n x n)
  ErrorVector g;      ///< C_j d_{j+1}  (n)
  ErrorMatrix Sigma;  ///< P_j|j − C_j P_{j+1|j} C_jᵀ  (n x n, symmetric)
};

/// One RTS step of the closed-loop filter (docs/fusion.md eqs. 12.4-12.7).
/// P_post: covariance of the error of the nominal state at step j after all of step j's updates [state units²];
/// Phi: error transition j -> j+1 (resets folded in; or the product of the transitions of a run of steps without
/// updates, eq. 12.13); P_prior: Φ P_post Φᵀ + Q_d, the covariance before step j+1's updates; A, d: the error
/// before step j+1's updates in terms of the error after them, δx⁻ = A δx + d (d = the corrections fed back into
/// the nominal state in step j+1, A = the covariance re-expressions).
RtsStep rts_step(const ErrorMatrix& P_post, const ErrorMatrix& Phi, const ErrorMatrix& P_prior, const ErrorMatrix& A,
                 const ErrorVector& d);
/// The same, written into `out` (no copy of the result).
void rts_step(const ErrorMatrix& P_post, const ErrorMatrix& Phi, const ErrorMatrix& P_prior, const ErrorMatrix& A,
              const ErrorVector& d, RtsStep& out);
/// The same with Φ P_post already computed (PhiP; the filter has it from its covariance prediction).
void rts_step(const ErrorMatrix& P_post, const ErrorMatrix& Phi, const ErrorMatrix& P_prior, const ErrorMatrix& A,
              const ErrorVector& d, const ErrorMatrix& PhiP, RtsStep& out);

/// Composition of consecutive steps between two output epochs a < b (docs/fusion.md eq. 12.9):
/// ŝ_a = M ŝ_b + m,  P_s,a = S + M P_s,b Mᵀ.
struct RtsSegment {
  ErrorMatrix M;
  ErrorVector m;
  ErrorMatrix S;
};

/// Composes steps forward in time (M ← M G, m ← m + M g, S ← S + M Σ Mᵀ) into one segment per output epoch
/// (reference formulation of the segments RtsInterval builds; tests and benchmarks).
class RtsAccumulator {
 public:
  /// Start an empty segment (identity map) for an n-dimensional error state.
  explicit RtsAccumulator(int n = 0) { reset(n); }
  /// Begin a new segment at the current step (the previous one has been taken with take()).
  void reset(int n);
  /// Append the backward map of the next step (steps must be appended in time order).
  void append(const RtsStep& step);
  /// The segment composed so far; the accumulator is reset to identity.
  RtsSegment take();
  /// Number of steps in the current segment.
  int steps() const { return steps_; }

 private:
  RtsSegment seg_;
  ErrorMatrix tmp_;
  int steps_ = 0;
};

/// Forward bookkeeping of the smoother over one interval between output epochs a < b (docs/fusion.md §12.3b,
/// eqs. 12.14-12.20), carried along with the filter's own events instead of a backward map per step:
/// Γ = Cov(δx_a, δx_j | Y_j) (the error at the interval's start against the current error), μ = E[δx_a | Y_j] and
/// V = Var(δx_a | Y_j). close() turns them into the segment (12.9) that rts_backward reads: M = Γ P_b|b⁻¹, m = μ,
/// S = V − M Γᵀ. Fixed-capacity storage: nothing is allocated per call (with fixed-capacity H, r, K).
class RtsInterval {
 public:
  /// An empty interval of an n-dimensional error state (restart() before use).
  explicit RtsInterval(int n = 0) { restart(ErrorMatrix::Zero(n, n)); }
  /// Start the interval at output epoch a: Γ = V = P_a|a (the filter covariance after all of a's updates), μ = 0
  /// (eq. 12.14).
  void restart(const ErrorMatrix& P_a);
  /// The same when the filter's error at a has a known non-zero conditional mean η_a = E[δx_a | Y_a] and P_a is
  /// Var(δx_a | Y_a): μ = η_a (the smoother of a filter with consider states, docs/fusion.md §12.6, eq. 12.21).
  void restart(const ErrorMatrix& P_a, const ErrorVector& eta_a);
  /// Prediction δx⁻ = Φ δx + w (w independent of δx_a): Γ ← Γ Φᵀ (eq. 12.15), Φ by its row structure: products
  /// over Φ's dense rows only; the columns of unit rows stay, those of scaled-unit rows are scaled.
  void predict(const RowTransition<ins::kMaxErrorDim>& Phi);
  /// The same with a dense Φ.
  void predict(const ErrorMatrix& Phi);
  /// A Kalman update of the filter with residual r (measured − predicted), Jacobian H (m × n), the factorization
  /// of its innovation covariance S = H P Hᵀ + R and the gain K = P Hᵀ S⁻¹ it used; the correction K r is fed back
  /// (closed loop) (eqs. 12.16-12.17): with L = Γ Hᵀ, μ ← μ + L S⁻¹ r, V ← V − L S⁻¹ Lᵀ, Γ ← Γ − L Kᵀ.
  template <typename MatH, typename VecR, typename Ldlt, typename MatK>
  void update(const MatH& H, const VecR& r, const Ldlt& S_ldlt, const MatK& K);
  /// Re-expression of the error coordinates δx_new = J δx_old, J = I + E_dst B E_srcᵀ on two disjoint 3-blocks
  /// (form D, docs/fusion.md eq. 5.9): Γ ← Γ Jᵀ (eq. 12.18).
  void reexpress(int dst, int src, const Eigen::Matrix3d& B);
  /// The filter fed back K r + delta instead of K r at state i, a state without process noise over the interval
  /// (a constant, or a slow Gauss-Markov state: the scale factors), and asserts the error after the update has zero
  /// mean (the errors-in-variables compensation of docs/consistency.md eq. E.4). For such a state Γ's row equals P's
  /// row (δx_a,i = δx_j,i + the corrections fed back since a), so E[δx_a,i | Y] moves by delta too: μ_i += delta
  /// (docs/consistency.md eq. E.6; the regression of δx_a's other components on the deviation is left out).
  void shift_mean(int i, double delta) { mu_(i) += delta; }
  /// The errors-in-variables bias of the interval's own conditioning (docs/consistency.md eq. E.7): Γ ← Γ Φᵀ with
  /// the noisy scale columns of Φ gives Γ a noise part Γ_{:,s} wᵀ — the same noise direction w that P's scale row
  /// carries as P_ss wᵀ (eq. E.2) — so μ += Γ Hᵀ S⁻¹ r picks up Γ_{:,s} / P_ss times the scale update's bias b_s in
  /// every component, not only in the scale row (eq. E.6). With deviations delta = −b at the scale states
  /// states[0..n) and P the filter covariance after the update: μ ← μ + Γ_{:,S} P_SS⁻¹ delta. In row s ∈ S (a
  /// constant: Γ_{s,S} = P_{s,S}) this is shift_mean(s, delta_s). Falls back to shift_mean per state when P_SS is not
  /// positive definite.
  void shift_mean_regressed(const int* states, const double* delta, int n, const ErrorMatrix& P);
  /// State i restarted as a fresh variable independent of everything before (clock, drift, multipath slot reset,
  /// docs/fusion.md §7, §12.4): Γ.col(i) ← 0 (eq. 12.19).
  void restart_state(int i);
  /// The segment of the interval a → b, P_b: the filter covariance at b after all its updates (eq. 12.20); the
  /// identity map if no step was predicted since restart().
  void close(const ErrorMatrix& P_b, RtsSegment& out) const;
  /// The same when the error at b has the conditional mean η_b = E[δx_b | Y_b] and P_b = Var(δx_b | Y_b):
  /// m = μ − M η_b (docs/fusion.md eq. 12.24).
  void close(const ErrorMatrix& P_b, const ErrorVector& eta_b, RtsSegment& out) const;
  /// Number of predictions since restart().
  int steps() const { return steps_; }
  /// The current Γ, μ, V (tests).
  const ErrorMatrix& cross() const { return Gamma_; }
  const ErrorVector& mean() const { return mu_; }
  const ErrorMatrix& var() const { return V_; }

 private:
  // The two close() overloads; eta_b null: zero conditional mean (no product).
  void close(const ErrorMatrix& P_b, const ErrorVector* eta_b, RtsSegment& out) const;

  ErrorMatrix Gamma_, V_, tmp_;
  ErrorVector mu_;
  int steps_ = 0;
};

template <typename MatH, typename VecR, typename Ldlt, typename MatK>
void RtsInterval::update(const MatH& H, const VecR& r, const Ldlt& S_ldlt, const MatK& K) {
  using ColsMatrix = Eigen::Matrix<double, Eigen::Dynamic, MatH::RowsAtCompileTime, Eigen::ColMajor, ins::kMaxErrorDim,
                                   MatH::MaxRowsAtCompileTime>;
  using RowsMatrix = Eigen::Matrix<double, MatH::RowsAtCompileTime, Eigen::Dynamic, Eigen::ColMajor,
                                   MatH::MaxRowsAtCompileTime, ins::kMaxErrorDim>;
  // L = Γ Hᵀ = Cov(δx_a, r | Y) (the measurement sees δx_a only through δx_j), as sums of whole columns of Γ over
  // the non-zeros of H (ZUPT + ZARU: 12 of 6 x 17): L.col(i) += H(i, j) Γ.col(j).
  ColsMatrix L;
  L.setZero(Gamma_.rows(), H.rows());
  for (int j = 0; j < H.cols(); ++j) {
    for (int i = 0; i < H.rows(); ++i) {
      const double h = H(i, j);
      if (h != 0.0) L.col(i) += h * Gamma_.col(j);
    }
  }
  const RowsMatrix W = S_ldlt.solve(L.transpose());  // S⁻¹ Lᵀ
  mu_.noalias() += W.transpose() * r;                // eq. 12.16: δx_a conditioned on the innovation
  V_.noalias() -= L * W;                             // eq. 12.16
  Gamma_.noalias() -= L * K.transpose();  // eq. 12.17: Cov(δx_a, δx⁻ − K r | y) = Γ − L S⁻¹ H P = Γ (I − K H)ᵀ
}

/// The stored segments, packed: per record M (n², column-major), m (n) and the upper triangle of the symmetric S
/// (n(n+1)/2), all double, in one array (one allocation growing geometrically, or none after reserve()).
/// For n = 17: 459 doubles = 3672 B per output epoch (docs/performance.md).
class RtsStore {
 public:
  explicit RtsStore(int n = 0) : n_(n) {}
  /// Pre-size for `records` records (no reallocation while pushing up to that many).
  void reserve(size_t records) { data_.reserve(records * record_doubles()); }
  /// Append one segment (its dimension must be n).
  void push(const RtsSegment& s);
  /// Segment i (0 = first).
  void get(size_t i, RtsSegment& out) const;
  size_t size() const { return n_ == 0 ? 0 : data_.size() / record_doubles(); }
  int dim() const { return n_; }
  /// Doubles per record: n² + n + n(n+1)/2.
  size_t record_doubles() const {
    const size_t n = static_cast<size_t>(n_);
    return n * n + n + n * (n + 1) / 2;
  }
  /// Bytes of the records held (for memory reporting).
  size_t bytes() const { return data_.size() * sizeof(double); }

 private:
  int n_;
  std::vector<double> data_;
};

/// Smoothed error estimate and covariance at each output epoch.
struct RtsSmoothed {
  Eigen::VectorXd dx;  ///< smoothed error of the forward nominal state at the output epoch (true ⊟ nominal)
  Eigen::MatrixXd P;   ///< its covariance
};

/// Backward pass (docs/fusion.md eq. 12.10): store record i maps output epoch i+1 onto output epoch i, tail maps the
/// last step onto the last output epoch, P_last is the filter covariance at the last step (where the smoothed and
/// filtered solutions coincide, ŝ = 0). Calls visit(i, ŝ_i, P_s,i) for i = store.size() down to 0.
void rts_backward(const RtsStore& store, const RtsSegment& tail, const ErrorMatrix& P_last,
                  const std::function<void(size_t, const ErrorVector&, const ErrorMatrix&)>& visit);
/// The same when the error at the last step has the conditional mean eta_last = E[δx_N | Y_N] (the smoothed error
/// there) and P_last = Var(δx_N | Y_N) (docs/fusion.md eq. 12.25).
void rts_backward(const RtsStore& store, const RtsSegment& tail, const ErrorMatrix& P_last,
                  const ErrorVector& eta_last,
                  const std::function<void(size_t, const ErrorVector&, const ErrorMatrix&)>& visit);

/// The same over segments held in a vector; returns one entry per output epoch (segments.size() + 1).
std::vector<RtsSmoothed> rts_backward(const std::vector<RtsSegment>& segments, const RtsSegment& tail,
                                      const ErrorMatrix& P_last);
/// The same with the conditional mean at the last step.
std::vector<RtsSmoothed> rts_backward(const std::vector<RtsSegment>& segments, const RtsSegment& tail,
                                      const ErrorMatrix& P_last, const ErrorVector& eta_last);

}  // namespace pednav::fusion
