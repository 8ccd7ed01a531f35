// SPDX-License-Identifier: BSD-2-Clause
// A state transition Φ stored by its row structure, and the covariance products the filter and the smoother need
// with it (docs/performance.md §5, issue 39). The error state of the engine has a few "dense" rows (navigation
// states: position, velocity, attitude; the receiver clock) and many unit or scaled-unit rows (random-walk and
// Gauss-Markov states: biases, scale factors, drift, multipath slots, consider states: Φ_rr = d_r and nothing else
// in the row). With G the dense rows and D = diag(d) the others, P ← Φ P Φᵀ + Q costs the products with Φ's
// dense rows only: U = P Φ_Gᵀ (n × |G|, sums of whole columns of P over the nonzeros), then
//   P_DD ← d_D d_Dᵀ ∘ P_DD + Q_DD,  P_DG ← D U_D + Q_DG,  P_GG ← Φ_G U + Q_GG,
// no work at all for a unit row beyond the addition of Q. Storage is inline (no heap allocation).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cassert>

#include "core/vector_kernels.hpp"

namespace pednav {

/// Φ (n × n, n ≤ kMaxDim) by rows: dense rows by their nonzeros, the other rows by their diagonal entry.
template <int kMaxDim>
class RowTransition {
 public:
  /// Capture Φ (square). A row whose only nonzero is its diagonal entry (or that is all zero) is a scaled unit
  /// row; every other row is kept by its nonzeros. Scans all n² entries.
  template <typename Mat>
  void assign(const Eigen::MatrixBase<Mat>& Phi) {
    assert(Phi.rows() == Phi.cols() && Phi.rows() <= kMaxDim);
    int all[kMaxDim];
    for (int r = 0; r < Phi.rows(); ++r) all[r] = r;
    assign(Phi, all, static_cast<int>(Phi.rows()));
  }
  /// The same when the model guarantees that every row outside rows[0..count) (increasing) has no off-diagonal
  /// nonzero — in the engine the navigation rows and the clock rows are the only candidates (docs/error_state.md
  /// eq. 3.1-3.8; tests/ins/test_error_state.cpp checks that structure): only the candidate rows are scanned (n ·
  /// count entries instead of n²). A candidate row without off-diagonal nonzeros is still a scaled unit row.
  template <typename Mat>
  void assign(const Eigen::MatrixBase<Mat>& Phi, const int* rows, int count) {
    assert(Phi.rows() == Phi.cols() && Phi.rows() <= kMaxDim);
    n_ = static_cast<int>(Phi.rows());
    n_dense_ = 0;
    int nz = 0;
    for (int r = 0; r < n_; ++r) d_[r] = Phi(r, r);
    for (int q = 0; q < count; ++q) {
      const int r = rows[q];
      assert(r >= 0 && r < n_ && (q == 0 || rows[q - 1] < r));
      const int first = nz;
      bool off_diagonal = false;
      for (int c = 0; c < n_; ++c) {
        const double v = Phi(r, c);
        if (v != 0.0) {
          col_[nz] = c;
          val_[nz] = v;
          ++nz;
          off_diagonal = off_diagonal || c != r;
        }
      }
      if (!off_diagonal) {
        nz = first;  // a scaled unit row after all
        continue;
      }
      d_[r] = 0.0;  // not used for a dense row (its entries of P are overwritten)
      dense_[n_dense_] = r;
      start_[n_dense_] = first;
      ++n_dense_;
    }
    start_[n_dense_] = nz;
#ifndef NDEBUG
    for (int r = 0, q = 0; r < n_; ++r) {
      if (q < count && rows[q] == r) {
        ++q;
        continue;
      }
      for (int c = 0; c < n_; ++c) assert(c == r || Phi(r, c) == 0.0);
    }
#endif
    all_unit_ = true;
    for (int r = 0, k = 0; r < n_; ++r) {
      if (k < n_dense_ && dense_[k] == r) {
        ++k;
      } else {
        all_unit_ = all_unit_ && d_[r] == 1.0;
      }
    }
  }

  int dim() const { return n_; }
  /// Number of dense rows and their row indices (increasing).
  int dense_rows() const { return n_dense_; }
  int dense_row(int k) const { return dense_[k]; }
  /// Nonzeros of the dense rows.
  int dense_nonzeros() const { return start_[n_dense_]; }

  /// P ← Φ P Φᵀ + Q for a symmetric P (n × n; exactly symmetric on return), Q symmetric n × n. U: scratch, resized
  /// to n × dense_rows(). Cost: n · dense_nonzeros() multiply-adds for U, about 2 n² for the rest (vectorized
  /// column passes), instead of n · nnz(Φ) · 3/2 for the column-sparse products of ColumnSparse.
  template <typename MatP, typename MatQ, typename MatU>
  void propagate_symmetric(MatP& P, const MatQ& Q, MatU& U) const {
    propagate<true>(P, &Q, U);
  }
  /// P ← Φ P Φᵀ without process noise (the errors-in-variables footprints, docs/consistency.md §3.6).
  template <typename MatP, typename MatU>
  void propagate_symmetric(MatP& P, MatU& U) const {
    propagate<false>(P, static_cast<const MatP*>(nullptr), U);
  }

  /// P_t ← Φ P_t Φᵀ (no process noise) for `count` symmetric n × n matrices stacked vertically in one column-major
  /// array s0 (block t = rows [t n, (t + 1) n), leading dimension count · n): the errors-in-variables footprints
  /// (docs/consistency.md §3.7). Each block gets exactly the arithmetic of propagate_symmetric(P_t, U), so the
  /// results are bit-identical; the products the blocks share a Φ for (U = P Φ_Gᵀ, Z = Φ_G U) run once as passes
  /// over count · n (count · dense_rows()) rows instead of count short ones. Scratch (not initialized): u of
  /// count · n · dense_rows(), ut of count · dense_rows() · n, zt of count · dense_rows()² doubles.
  void propagate_stacked(double* s0, int count, double* u0, double* ut, double* zt) const {
    const int n = n_, m = n_dense_;
    const Eigen::Index ld = static_cast<Eigen::Index>(count) * n, ldt = static_cast<Eigen::Index>(count) * m;
    times_dense_rows_into(s0, ld, ld, u0, ld);  // U = S Φ_Gᵀ, all blocks at once
    int k = 0;
    for (int j = 0; j < n; ++j) {  // unit and scaled-unit columns: P_t(:, j) ← d_j d ∘ P_t(:, j)
      if (k < m && dense_[k] == j) {
        ++k;
        continue;
      }
      if (!all_unit_) {
        for (int t = 0; t < count; ++t) kernels::scale_by_outer(n, d_[j], d_.data(), s0 + j * ld + t * n);
      }
    }
    // Uᵀ of every block, stacked: ut((t m + kk), i) = U_t(i, kk); then Zᵀ = Φ_G-sums of its columns, all blocks.
    for (int i = 0; i < n; ++i) {
      for (int t = 0; t < count; ++t) {
        for (int kk = 0; kk < m; ++kk) ut[t * m + kk + i * ldt] = u0[t * n + i + kk * ld];
      }
    }
    times_dense_rows_into(ut, ldt, ldt, zt, ldt);  // zt(t m + kk, l) = Z_t(l, kk)
    for (int t = 0; t < count; ++t) {  // dense columns, then mirrored into their rows (as in propagate)
      double* const pt = s0 + t * n;
      for (k = 0; k < m; ++k) {
        const int j = dense_[k];
        double* const pj = pt + j * ld;
        kernels::multiply(n, d_.data(), u0 + t * n + k * ld, pj);
        for (int l = 0; l <= k; ++l) pj[dense_[l]] = zt[t * m + k + l * ldt];
        for (int i = 0; i < n; ++i) pt[j + i * ld] = pj[i];
      }
    }
  }

  /// A ← A Φᵀ (A: any number of rows × n; the smoother's cross-covariance Γ, docs/fusion.md eq. 12.15). U: scratch of
  /// at least A.rows() × dense_rows(). Unit columns are not touched, scaled-unit columns scaled.
  template <typename MatA, typename MatU>
  void times_transposed_in_place(MatA& A, MatU& U) const {
    assert(A.cols() == n_);
    U.resize(A.rows(), n_dense_);
    times_transposed_dense_rows(A, U);
    int k = 0;
    for (int j = 0; j < n_; ++j) {
      if (k < n_dense_ && dense_[k] == j) {
        A.col(j) = U.col(k);
        ++k;
      } else if (d_[j] != 1.0) {
        A.col(j) *= d_[j];
      }
    }
  }

  /// x ← Φ x (tmp: scratch vector of n).
  template <typename Vec>
  void times_in_place(Vec& x, Vec& tmp) const {
    tmp.resize(n_dense_);
    for (int k = 0; k < n_dense_; ++k) {
      double s = 0.0;
      for (int e = start_[k]; e < start_[k + 1]; ++e) s += val_[e] * x(col_[e]);
      tmp(k) = s;
    }
    int k = 0;
    for (int j = 0; j < n_; ++j) {
      if (k < n_dense_ && dense_[k] == j) {
        x(j) = tmp(k);
        ++k;
      } else {
        x(j) *= d_[j];
      }
    }
  }

 private:
  template <bool kWithQ, typename MatP, typename MatQ, typename MatU>
  void propagate(MatP& P, const MatQ* Q, MatU& U) const {
    assert(P.rows() == n_ && P.cols() == n_);
    const int n = n_;
    U.resize(n, n_dense_);
    times_transposed_dense_rows(P, U);  // U = P Φ_Gᵀ = (Φ_G P)ᵀ
    const Eigen::Index ldp = P.outerStride(), ldu = U.outerStride();
    double* const p0 = P.data();
    const double* const u0 = U.data();
    const double* q0 = nullptr;
    Eigen::Index ldq = 0;
    if constexpr (kWithQ) {
      q0 = Q->data();
      ldq = Q->outerStride();
    }
    // Unit and scaled-unit columns j: P(:, j) ← d_j d ∘ P(:, j) + Q(:, j) (the entries in dense rows are overwritten
    // below). d_i d_j = d_j d_i exactly: this block stays exactly symmetric.
    int k = 0;
    for (int j = 0; j < n; ++j) {
      if (k < n_dense_ && dense_[k] == j) {
        ++k;
        continue;
      }
      double* const pj = p0 + j * ldp;
      if (!all_unit_) kernels::scale_by_outer(n, d_[j], d_.data(), pj);
      if constexpr (kWithQ) kernels::add(n, q0 + j * ldq, pj);
    }
    // The dense block Z = Φ_G U (m × m, Z_lk = Φ(g_l, :) U(:, k)) by columns of Zᵀ: Zᵀ(:, l) = Σ_e Φ(g_l, c_e) Uᵀ(:, c_e),
    // sums of whole columns of Uᵀ (m × n, transposed once).
    const int m = n_dense_;
    double Ut[kMaxDim * kMaxDim];  // not initialized: every entry read is written first
    double Zt[kMaxDim * kMaxDim];
    for (int kk = 0; kk < m; ++kk) {
      for (int i = 0; i < n; ++i) Ut[kk + i * m] = u0[i + kk * ldu];
    }
    times_dense_rows_into(Ut, m, m, Zt);
    // Dense columns j = g_k: P(i, j) = d_i U(i, k) in the other rows, Z_lk in dense rows g_l with l ≤ k (l > k: set
    // by symmetry when column g_l is done), + Q(i, j); column j is then mirrored into row j.
    for (k = 0; k < m; ++k) {
      const int j = dense_[k];
      double* const pj = p0 + j * ldp;
      kernels::multiply(n, d_.data(), u0 + k * ldu, pj);
      if constexpr (kWithQ) kernels::add(n, q0 + j * ldq, pj);
      for (int l = 0; l <= k; ++l) {
        double s = Zt[k + l * m];
        if constexpr (kWithQ) s += q0[dense_[l] + j * ldq];
        pj[dense_[l]] = s;
      }
      for (int i = 0; i < n; ++i) p0[j + i * ldp] = pj[i];
    }
  }

  // U(:, k) = Σ_c Φ(g_k, c) A(:, c): the dense rows' part of A Φᵀ, as sums of whole columns of A, four columns per
  // pass over U(:, k) (core/vector_kernels: at these sizes Eigen's per-expression set-up costs as much as the
  // arithmetic).
  template <typename MatA, typename MatU>
  void times_transposed_dense_rows(const MatA& A, MatU& U) const {
    times_dense_rows_into(A.data(), A.outerStride(), A.rows(), U.data(), U.outerStride());
  }
  // The same on raw column-major storage: A (rows × n, leading dimension lda) into U (rows × dense_rows(), ldu).
  void times_dense_rows_into(const double* a0, Eigen::Index lda, Eigen::Index rows, double* u0,
                             Eigen::Index ldu = -1) const {
    if (ldu < 0) ldu = rows;
    for (int k = 0; k < n_dense_; ++k) {
      double* const u = u0 + k * ldu;
      for (Eigen::Index i = 0; i < rows; ++i) u[i] = 0.0;
      int e = start_[k];
      const int end = start_[k + 1];
      for (; e + 4 <= end; e += 4) {
        kernels::axpy4(rows, &val_[e], a0 + col_[e] * lda, a0 + col_[e + 1] * lda, a0 + col_[e + 2] * lda,
                       a0 + col_[e + 3] * lda, u);
      }
      if (e + 2 <= end) {
        kernels::axpy2(rows, &val_[e], a0 + col_[e] * lda, a0 + col_[e + 1] * lda, u);
        e += 2;
      }
      if (e < end) kernels::axpy1(rows, val_[e], a0 + col_[e] * lda, u);
    }
  }

  int n_ = 0, n_dense_ = 0;
  bool all_unit_ = true;  // every non-dense row is a unit row (d_r = 1)
  std::array<double, kMaxDim> d_;       // diagonal entry of each non-dense row
  std::array<int, kMaxDim> dense_;      // dense row indices, increasing
  std::array<int, kMaxDim + 1> start_;  // not value-initialized: assign() writes what is read
  std::array<int, kMaxDim * kMaxDim> col_;
  std::array<double, kMaxDim * kMaxDim> val_;
};

}  // namespace pednav
