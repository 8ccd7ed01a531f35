// SPDX-License-Identifier: BSD-2-Clause
// ColumnSparse (core/column_sparse.hpp): the products that skip zeros equal the dense products, for the engine's
// sizes and the edges, on matrices shaped like Φ of the INS error model (dense 3×3 blocks and scattered entries).
#include <gtest/gtest.h>

#include <random>

#include "core/column_sparse.hpp"

namespace pednav {
namespace {

using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 40, 40>;

// A: identity plus dense 3×3 blocks at some aligned positions, plus scattered single entries (like Φ of the INS
// error model with clock, drift and multipath states after the 3-blocks).
Mat structured(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd;
  std::bernoulli_distribution dense_block(0.3), single(0.05);
  Mat A = Mat::Identity(n, n);
  for (int c0 = 0; c0 + 3 <= n; c0 += 3)
    for (int r0 = 0; r0 + 3 <= n; r0 += 3)
      if (dense_block(rng))
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i) A(r0 + i, c0 + j) = nd(rng);
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r)
      if (A(r, c) == 0.0 && single(rng)) A(r, c) = nd(rng);
  return A;
}

class ColumnSparseSizes : public ::testing::TestWithParam<int> {};

TEST_P(ColumnSparseSizes, ProductsEqualTheDenseOnes) {
  const int n = GetParam();
  std::mt19937 rng(5u + static_cast<unsigned>(n));
  std::normal_distribution<double> nd;
  const Mat A = structured(n, 17u + static_cast<unsigned>(n));
  Mat X(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) X(i, j) = nd(rng);
  ColumnSparse<40> S;
  S.assign(A);
  EXPECT_EQ(S.nonzeros(), (A.array() != 0.0).count());

  Mat out = Mat::Constant(n, n, 0.5);  // out += …: the previous content must be kept
  S.add_times_transposed(X, out);
  const Eigen::MatrixXd expected = Eigen::MatrixXd::Constant(n, n, 0.5) + Eigen::MatrixXd(X) * Eigen::MatrixXd(A).transpose();
  EXPECT_LT((Eigen::MatrixXd(out) - expected).cwiseAbs().maxCoeff(), 1e-12);

  // Upper triangle of a symmetric product: X Aᵀ with X = A P (P symmetric) is A P Aᵀ; the strict lower triangle of
  // `up` is not touched.
  Mat P = X * X.transpose();
  const Mat AP = A * P;
  Mat up = Mat::Zero(n, n);
  S.add_times_transposed_upper(AP, up);
  const Eigen::MatrixXd sym = Eigen::MatrixXd(A) * Eigen::MatrixXd(P) * Eigen::MatrixXd(A).transpose();
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i <= j; ++i) EXPECT_NEAR(up(i, j), sym(i, j), 1e-10 * sym.cwiseAbs().maxCoeff()) << i << "," << j;
    for (int i = j + 1; i < n; ++i) EXPECT_EQ(up(i, j), 0.0) << i << "," << j;
  }

  Mat AX;
  S.times(X, AX);
  EXPECT_LT((Eigen::MatrixXd(AX) - Eigen::MatrixXd(A) * Eigen::MatrixXd(X)).cwiseAbs().maxCoeff(), 1e-12);
}

// 17 and 29: the engine's sizes (white code; with 12 multipath states); 1-3, 16 and 40: edges and the capacity.
INSTANTIATE_TEST_SUITE_P(Sizes, ColumnSparseSizes, ::testing::Values(1, 2, 3, 16, 17, 29, 40));

}  // namespace
}  // namespace pednav
