// SPDX-License-Identifier: BSD-2-Clause
// The EKF covariance prediction and Joseph-form update of the forward engine on fixed-capacity matrices
// (ins::ErrorMatrix: sized at run time, stored inline): no heap allocation when the measurement matrices have a
// fixed capacity too (docs/performance.md). Used by fusion/error_state_filter and the benchmarks in bench/.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "core/row_transition.hpp"
#include "core/vector_kernels.hpp"
#include "ins/error_state.hpp"

namespace pednav::fusion {

/// P ← Φ P Φᵀ + Q_d, symmetrized (Groves 2013 eq. 3.15); tmp is scratch space.
/// P: error covariance [state units²]; Phi: error transition over the step; Qd: discrete process noise.
inline void covariance_predict(ins::ErrorMatrix& P, const ins::ErrorMatrix& Phi, const ins::ErrorMatrix& Qd,
                               ins::ErrorMatrix& tmp) {
  tmp.noalias() = Phi * P;
  P = Qd;
  P.noalias() += tmp * Phi.transpose();
  P = 0.5 * (P + P.transpose()).eval();
}

/// Mirror the upper triangle of the square matrix A into its strict lower triangle (exact symmetry).
template <typename Mat>
inline void mirror_upper(Mat& A) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = j + 1; i < n; ++i) A(i, j) = A(j, i);
  }
}

/// The same with Φ by its row structure (core/row_transition.hpp): the products run over Φ's dense rows only (the
/// navigation states and the clock); the unit and scaled-unit rows of the random-walk and Gauss-Markov states
/// (biases, scale factors, drift, multipath slots, consider states) cost one scaling of their entries of P:
/// U = P Φ_Gᵀ, then P_DD ← d dᵀ ∘ P_DD, P_DG ← D U_D, P_GG ← Φ_G U, + Q_d, computed in place and exactly symmetric
/// (docs/performance.md §5). tmp: scratch (n × number of dense rows on return).
inline void covariance_predict(ins::ErrorMatrix& P, const RowTransition<ins::kMaxErrorDim>& Phi,
                               const ins::ErrorMatrix& Qd, ins::ErrorMatrix& tmp) {
  Phi.propagate_symmetric(P, Qd, tmp);
}

/// The indices of H's columns that are not all zero, in increasing order, into nz (capacity H.cols()); their count.
template <typename MatH>
inline int nonzero_columns(const MatH& H, int* nz) {
  int n = 0;
  for (int c = 0; c < H.cols(); ++c) {
    if (!H.col(c).isZero(0.0)) nz[n++] = c;
  }
  return n;
}

/// X ← (I − K H) X (I − K H)ᵀ + K R Kᵀ for a symmetric X given U = X Hᵀ (n × m) and S = H U + R (m × m, symmetric):
/// X − K Wᵀ − W Kᵀ with W = U − ½ K S (docs/fusion.md eq. 6.4), a symmetric rank-2m update on the upper triangle,
/// mirrored — n(n+1)·m multiply-adds. With R = 0 it is the plain (I − K H) X (I − K H)ᵀ. X: a matrix or a block of
/// one (column-major, unit inner stride); K likewise. The column updates are kernels over contiguous memory:
/// at the engine's sizes (n ≤ 48, m = 6) Eigen's per-expression set-up cost more than the arithmetic, and a GEMM
/// (Y = W Kᵀ, X − Y − Yᵀ, or the triangular product) more than both (issue 39, docs/performance.md §5).
template <typename MatX, typename MatU, typename MatK, typename MatS>
inline void gain_downdate(MatX& X, const MatU& U, const MatK& K, const MatS& S) {
  const Eigen::Index n = X.rows(), m = K.cols();
  MatU W = U;  // W = U − ½ K S, by columns: W(:, k) −= ½ S(l, k) K(:, l)
  for (Eigen::Index k = 0; k < m; ++k) {
    for (Eigen::Index l = 0; l < m; ++l) kernels::axpy1(n, -0.5 * S(l, k), K.col(l).data(), W.col(k).data());
  }
  const Eigen::Index ldx = X.outerStride(), ldk = K.outerStride(), ldw = W.outerStride();
  double* const x0 = X.data();
  const double* const k0 = K.data();
  const double* const w0 = W.data();
  for (Eigen::Index j = 0; j < n; ++j) {
    double* const x = x0 + j * ldx;
    for (Eigen::Index k = 0; k < m; ++k) {
      kernels::rank2_downdate(j + 1, w0[j + k * ldw], k0 + k * ldk, k0[j + k * ldk], w0 + k * ldw, x);
    }
  }
  mirror_upper(X);
}

/// Joseph-form Kalman update (Groves 2013 eqs. 3.18, 3.22): K = P Hᵀ (H P Hᵀ + R)⁻¹, dx = K r,
/// P ← (I − K H) P (I − K H)ᵀ + K R Kᵀ, symmetrized. r: residuals (measured − predicted) [measurement units],
/// H: Jacobian w.r.t. the error state (m × n), R: measurement noise covariance (m × m). Returns false (P and dx
/// untouched) if H P Hᵀ + R is not positive definite. With fixed-capacity H, r and R nothing is allocated.
/// on_gain(ldlt, K) is called with the factorization of H P Hᵀ + R and the gain before P changes (the smoother's
/// bookkeeping, fusion::RtsInterval::update).
/// Consider states (Schmidt–Kalman, docs/error_state.md §5): the rows [consider.begin, consider.begin + count) of K
/// are set to zero — those states are never corrected, but their uncertainty stays in P and reaches the others
/// through Φ; the expanded Joseph form below is exact for that gain.
struct ConsiderStates {
  int begin = 0;
  int count = 0;
};
template <typename MatH, typename VecR, typename MatR, typename OnGain>
bool joseph_update(ins::ErrorMatrix& P, const MatH& H, const VecR& r, const MatR& R, ins::ErrorVector& dx,
                   OnGain&& on_gain, ConsiderStates consider = {}) {
  using ColsMatrix = Eigen::Matrix<double, Eigen::Dynamic, MatH::RowsAtCompileTime, Eigen::ColMajor,
                                   ins::kMaxErrorDim, MatH::MaxRowsAtCompileTime>;
  using SMatrix = Eigen::Matrix<double, MatH::RowsAtCompileTime, MatH::RowsAtCompileTime, Eigen::ColMajor,
                                MatH::MaxRowsAtCompileTime, MatH::MaxRowsAtCompileTime>;
  // H of a ZUPT or GNSS epoch touches a few states only (ZUPT: velocity, attitude, gyro bias): P Hᵀ and T Hᵀ are
  // summed over H's non-zero columns (n·m per column instead of n·n·m for the whole product).
  int nz[ins::kMaxErrorDim];
  const int n_nz = nonzero_columns(H, nz);
  auto times_Ht = [&](const ins::ErrorMatrix& A, ColsMatrix& out) {
    out.setZero(A.rows(), H.rows());
    for (int k = 0; k < n_nz; ++k) out.noalias() += A.col(nz[k]) * H.col(nz[k]).transpose();
  };
  ColsMatrix PHt;
  times_Ht(P, PHt);
  SMatrix S = R;
  S.noalias() += H * PHt;
  const Eigen::LDLT<SMatrix> ldlt(S);
  // Eigen's LDLT reports success for indefinite matrices too: positive definite means every pivot D_ii > 0.
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) return false;
  ColsMatrix K = ldlt.solve(PHt.transpose()).transpose();
  if (consider.count > 0) K.middleRows(consider.begin, consider.count).setZero();
  dx.noalias() = K * r;
  on_gain(ldlt, K);
  // Joseph form, expanded (exact for any gain K, so a rounding error in K still enters P only to second order):
  // (I − K H) P (I − K H)ᵀ + K R Kᵀ = P − K Uᵀ − U Kᵀ + K S Kᵀ with U = P Hᵀ and S = H U + R
  //                                 = P − K Wᵀ − W Kᵀ with W = U − ½ K S
  // (docs/fusion.md eq. 6.4): a symmetric rank-2m update, computed on the upper triangle and mirrored — n(n+1)·m
  // multiply-adds instead of the two n×m×n products of T = P − K H P, T − (T Hᵀ − K R) Kᵀ.
  gain_downdate(P, PHt, K, S);
  return true;
}

/// The same without a callback.
template <typename MatH, typename VecR, typename MatR>
bool joseph_update(ins::ErrorMatrix& P, const MatH& H, const VecR& r, const MatR& R, ins::ErrorVector& dx) {
  return joseph_update(P, H, r, R, dx, [](const auto&, const auto&) {});
}

}  // namespace pednav::fusion
