// SPDX-License-Identifier: BSD-2-Clause
// RowTransition (core/row_transition.hpp): Φ P Φᵀ + Q, A Φᵀ and Φ x over Φ's dense rows equal the dense products,
// P stays exactly symmetric, for the engine's sizes and the edges, on matrices shaped like the engine's Φ (dense
// navigation and clock rows; unit rows of random walks; scaled unit rows of Gauss-Markov states; a zero row).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/row_transition.hpp"

namespace pednav {
namespace {

using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 48, 48>;
using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 48, 1>;
constexpr double kTolRel = 1e-13;  // relative to the largest entry: reordered sums of ≤ 48 terms

// Rows 0..min(9, n)-1 dense with some zeros (navigation), row 9 dense over two entries (clock + drift dt), every
// third later row scaled by a Gauss-Markov factor, row n-1 zero (a state restarted to nothing), the rest unit rows.
Mat structured(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd;
  std::bernoulli_distribution keep(0.6);
  Mat A = Mat::Identity(n, n);
  for (int r = 0; r < std::min(9, n); ++r)
    for (int c = 0; c < std::min(21, n); ++c)
      if (c != r && keep(rng)) A(r, c) = 0.1 * nd(rng);
  if (n > 10) A(9, 10) = 0.05;
  for (int r = 11; r < n; r += 3) A(r, r) = 0.97;
  if (n > 12) A(n - 1, n - 1) = 0.0;
  return A;
}

Mat random_spd(int n, std::mt19937& rng) {
  std::normal_distribution<double> nd;
  Mat X(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) X(i, j) = nd(rng);
  Mat S = X * X.transpose();
  return 0.5 * (S + S.transpose());  // exactly symmetric, as the filter keeps P
}

double rel_diff(const Mat& a, const Eigen::MatrixXd& b) {
  return (Eigen::MatrixXd(a) - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

class RowTransitionSizes : public ::testing::TestWithParam<int> {};

TEST_P(RowTransitionSizes, ProductsEqualTheDenseOnesAndPStaysSymmetric) {
  const int n = GetParam();
  std::mt19937 rng(5u + static_cast<unsigned>(n));
  const Mat Phi = structured(n, 17u + static_cast<unsigned>(n));
  RowTransition<48> T;
  T.assign(Phi);
  int dense = 0;
  for (int r = 0; r < n; ++r) {
    bool off = false;
    for (int c = 0; c < n; ++c) off = off || (c != r && Phi(r, c) != 0.0);
    dense += off ? 1 : 0;
  }
  EXPECT_EQ(T.dense_rows(), dense);
  const Eigen::MatrixXd F(Phi);
  const Mat P0 = random_spd(n, rng), Q = 1e-3 * random_spd(n, rng);
  Mat U;

  Mat P = P0;
  T.propagate_symmetric(P, Q, U);
  EXPECT_LT(rel_diff(P, F * Eigen::MatrixXd(P0) * F.transpose() + Eigen::MatrixXd(Q)), kTolRel);
  EXPECT_EQ((P - P.transpose()).cwiseAbs().maxCoeff(), 0.0);

  P = P0;
  T.propagate_symmetric(P, U);  // without process noise
  EXPECT_LT(rel_diff(P, F * Eigen::MatrixXd(P0) * F.transpose()), kTolRel);
  EXPECT_EQ((P - P.transpose()).cwiseAbs().maxCoeff(), 0.0);

  // A Φᵀ for a non-symmetric A with fewer rows than columns (the smoother's Γ is square, but nothing needs it).
  Mat A = random_spd(n, rng);
  A(0, n - 1) += 1.0;
  const Eigen::MatrixXd expected_A = Eigen::MatrixXd(A) * F.transpose();
  T.times_transposed_in_place(A, U);
  EXPECT_LT(rel_diff(A, expected_A), kTolRel);

  std::normal_distribution<double> nd;
  Vec x(n), tmp;
  for (int i = 0; i < n; ++i) x(i) = nd(rng);
  const Eigen::VectorXd expected_x = F * Eigen::VectorXd(x);
  T.times_in_place(x, tmp);
  EXPECT_LT((Eigen::VectorXd(x) - expected_x).cwiseAbs().maxCoeff(),
            kTolRel * expected_x.cwiseAbs().maxCoeff() + 1e-15);
}

// The stacked form (the six errors-in-variables footprints of the filter, fusion/error_state_filter.hpp) gives every
// block exactly — bit for bit — what propagate_symmetric gives it alone, for 1 to 6 blocks; the blocks differ, and a
// scaled-unit row (all_unit_ false) and a zero row are in Φ.
TEST_P(RowTransitionSizes, StackedBlocksEqualSeparatePropagationBitForBit) {
  const int n = GetParam();
  std::mt19937 rng(31u + static_cast<unsigned>(n));
  const Mat Phi = structured(n, 41u + static_cast<unsigned>(n));
  RowTransition<48> T;
  T.assign(Phi);
  const int m = T.dense_rows();
  for (int count : {1, 2, 6}) {
    std::vector<Mat> blocks;
    for (int t = 0; t < count; ++t) blocks.push_back(random_spd(n, rng));
    const Eigen::Index ld = static_cast<Eigen::Index>(count) * n;
    std::vector<double> s(static_cast<size_t>(ld * n)), u(static_cast<size_t>(ld * std::max(m, 1))),
        ut(static_cast<size_t>(count * std::max(m, 1) * n)), zt(static_cast<size_t>(count * std::max(m * m, 1)));
    for (int t = 0; t < count; ++t)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) s[static_cast<size_t>(t * n + i + j * ld)] = blocks[t](i, j);
    T.propagate_stacked(s.data(), count, u.data(), ut.data(), zt.data());
    Mat U;
    for (int t = 0; t < count; ++t) {
      Mat expected = blocks[t];
      T.propagate_symmetric(expected, U);
      double worst = 0.0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          worst = std::max(worst, std::abs(s[static_cast<size_t>(t * n + i + j * ld)] - expected(i, j)));
      EXPECT_EQ(worst, 0.0) << "n " << n << " count " << count << " block " << t;
    }
  }
}

TEST(RowTransition, IdentityLeavesPAndAddsQ) {
  const int n = 20;
  std::mt19937 rng(3u);
  RowTransition<48> T;
  T.assign(Mat::Identity(n, n));
  EXPECT_EQ(T.dense_rows(), 0);
  const Mat P0 = random_spd(n, rng), Q = random_spd(n, rng);
  Mat P = P0, U;
  T.propagate_symmetric(P, Q, U);
  EXPECT_EQ((P - (P0 + Q)).cwiseAbs().maxCoeff(), 0.0);  // unit rows: P + Q exactly
}

// 1-3: edges; 17, 29, 35: the engine's sizes (white code; multipath; default tc with scale factors); 44 and 48:
// with the g-sensitivity consider states, and the capacity.
INSTANTIATE_TEST_SUITE_P(Sizes, RowTransitionSizes, ::testing::Values(1, 2, 3, 17, 29, 35, 44, 48));

}  // namespace
}  // namespace pednav
