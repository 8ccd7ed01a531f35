// Rauch-Tung-Striebel smoothing of a closed-loop (feedback) error-state filter, as pure linear algebra: no INS,
// no I/O. The forward filter hands over, per mechanization step, its posterior covariance, the transition and the
// prior covariance of the next step, and how that next step's updates moved the nominal state; the accumulator
// composes the per-step backward recursion between output epochs so that only one record per output epoch is
// stored (docs/fusion.md §12 "Smoother", eqs. 12.1-12.12).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace pednav::fusion {

/// Backward map of one step j -> j+1 (docs/fusion.md eq. 12.7): ŝ_j = G ŝ_{j+1} + g,  P_s,j = Σ + G P_s,{j+1} Gᵀ.
struct RtsStep {
  Eigen::MatrixXd G;      ///< C_j A_{j+1}  (n x n)
  Eigen::VectorXd g;      ///< C_j d_{j+1}  (n)
  Eigen::MatrixXd Sigma;  ///< P_j|j − C_j P_{j+1|j} C_jᵀ  (n x n, symmetric)
};

/// One RTS step of the closed-loop filter (docs/fusion.md eqs. 12.4-12.7).
/// P_post: covariance of the error of the nominal state at step j after all of step j's updates [state units²];
/// Phi: error transition j -> j+1 (resets folded in); P_prior: Φ P_post Φᵀ + Q_d, the covariance before step
/// j+1's updates; A, d: the error before step j+1's updates in terms of the error after them, δx⁻ = A δx + d
/// (d = the corrections fed back into the nominal state in step j+1, A = the covariance re-expressions).
RtsStep rts_step(const Eigen::MatrixXd& P_post, const Eigen::MatrixXd& Phi, const Eigen::MatrixXd& P_prior,
                 const Eigen::MatrixXd& A, const Eigen::VectorXd& d);

/// Composition of consecutive steps between two output epochs a < b (docs/fusion.md eq. 12.9):
/// ŝ_a = M ŝ_b + m,  P_s,a = S + M P_s,b Mᵀ.
struct RtsSegment {
  Eigen::MatrixXd M;
  Eigen::VectorXd m;
  Eigen::MatrixXd S;
  /// Bytes of heap storage of this record (for memory reporting).
  size_t bytes() const { return sizeof(double) * static_cast<size_t>(M.size() + m.size() + S.size()); }
};

/// Composes steps forward in time (M ← M G, m ← m + M g, S ← S + M Σ Mᵀ) into one segment per output epoch.
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
  int steps_ = 0;
};

/// Smoothed error estimate and covariance at each output epoch.
struct RtsSmoothed {
  Eigen::VectorXd dx;  ///< smoothed error of the forward nominal state at the output epoch (true ⊟ nominal)
  Eigen::MatrixXd P;   ///< its covariance
};

/// Backward pass (docs/fusion.md eq. 12.10): segments[i] maps output epoch i+1 onto output epoch i, tail maps the
/// last step onto the last output epoch, P_last is the filter covariance at the last step (where the smoothed and
/// filtered solutions coincide, ŝ = 0). Returns one entry per output epoch (segments.size() + 1).
std::vector<RtsSmoothed> rts_backward(const std::vector<RtsSegment>& segments, const RtsSegment& tail,
                                      const Eigen::MatrixXd& P_last);

}  // namespace pednav::fusion
