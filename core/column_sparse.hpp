// SPDX-License-Identifier: BSD-2-Clause
// Products with small matrices that are mostly zeros (the INS error model's F, G and Φ: 60-80 % zeros), skipping the
// zeros. Storage is inline (no heap allocation): up to kMaxDim x kMaxDim. Used on the per-step path of the filter
// (docs/performance.md).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cassert>

namespace pednav {

/// The nonzero entries of a dense matrix of at most kMaxDim x kMaxDim, column by column (compressed sparse column).
template <int kMaxDim>
class ColumnSparse {
 public:
  /// Capture the nonzeros of A (rows, cols <= kMaxDim).
  template <typename Mat>
  void assign(const Eigen::MatrixBase<Mat>& A) {
    assert(A.rows() <= kMaxDim && A.cols() <= kMaxDim);
    rows_ = static_cast<int>(A.rows());
    cols_ = static_cast<int>(A.cols());
    int n = 0;
    for (int c = 0; c < cols_; ++c) {
      start_[c] = n;
      for (int r = 0; r < rows_; ++r) {
        const double v = A(r, c);
        if (v != 0.0) {
          row_[n] = r;
          val_[n] = v;
          ++n;
        }
      }
    }
    start_[cols_] = n;
  }
  int rows() const { return rows_; }
  int cols() const { return cols_; }
  int nonzeros() const { return start_[cols_]; }

  /// out = A X  (out: rows() x X.cols(); out must not alias X).
  template <typename MatX, typename MatOut>
  void times(const Eigen::MatrixBase<MatX>& X, MatOut& out) const {
    out.setZero(rows_, X.cols());
    for (int j = 0; j < X.cols(); ++j) {
      for (int c = 0; c < cols_; ++c) {
        const double x = X(c, j);
        if (x == 0.0) continue;
        for (int k = start_[c]; k < start_[c + 1]; ++k) out(row_[k], j) += val_[k] * x;
      }
    }
  }

  /// out += X Aᵀ  (out: X.rows() x rows(), already sized; out must not alias X).
  template <typename MatX, typename MatOut>
  void add_times_transposed(const Eigen::MatrixBase<MatX>& X, MatOut& out) const {
    for (int c = 0; c < cols_; ++c) {
      for (int k = start_[c]; k < start_[c + 1]; ++k) out.col(row_[k]) += val_[k] * X.col(c);
    }
  }

  /// The upper triangle of out += X Aᵀ (out square, rows() x rows(); its strict lower triangle is not touched):
  /// for a product known to be symmetric (Φ P Φᵀ), half the work.
  template <typename MatX, typename MatOut>
  void add_times_transposed_upper(const Eigen::MatrixBase<MatX>& X, MatOut& out) const {
    for (int c = 0; c < cols_; ++c) {
      for (int k = start_[c]; k < start_[c + 1]; ++k) {
        const int r = row_[k];
        out.col(r).head(r + 1) += val_[k] * X.col(c).head(r + 1);
      }
    }
  }

 private:
  int rows_ = 0, cols_ = 0;
  std::array<int, kMaxDim + 1> start_;  // not value-initialized: assign() writes what is read (no 12 kB memset)
  std::array<int, kMaxDim * kMaxDim> row_;
  std::array<double, kMaxDim * kMaxDim> val_;
};

}  // namespace pednav
