// SPDX-License-Identifier: BSD-2-Clause
// The engine's covariance prediction and Joseph update (fusion/kalman.hpp) against their textbook dense forms:
// P ← Φ P Φᵀ + Q_d and P ← (I − K H) P (I − K H)ᵀ + K R Kᵀ (Groves 2013 eqs. 3.15, 3.22). The fast paths work on
// the non-zeros of Φ and H and on the upper triangle only (docs/performance.md §1, docs/fusion.md eq. 6.4), so the
// result must equal the dense form to rounding and be exactly symmetric.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "core/row_transition.hpp"
#include "fusion/kalman.hpp"
#include "ins/error_state.hpp"

namespace pednav {
namespace {

using ins::ErrorMatrix;
using ins::ErrorVector;
using H6 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, ins::kMaxErrorDim>;
using R6 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6>;
using V6 = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 6, 1>;

ErrorMatrix random_spd(int n, std::mt19937& rng) {
  std::normal_distribution<double> nd;
  Eigen::MatrixXd L(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) L(i, j) = nd(rng);
  Eigen::MatrixXd P = L * L.transpose() / n + 0.1 * Eigen::MatrixXd::Identity(n, n);
  // Exactly symmetric, as the filter keeps it.
  P = (0.5 * (P + P.transpose())).eval();
  return ErrorMatrix(P);
}

// Relative difference of A and B in the max norm.
double rel_diff(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  return (A - B).cwiseAbs().maxCoeff() / B.cwiseAbs().maxCoeff();
}

class KalmanSizes : public ::testing::TestWithParam<int> {};

TEST_P(KalmanSizes, SparsePredictionEqualsDenseAndIsSymmetric) {
  const int n = GetParam();
  std::mt19937 rng(7u + static_cast<unsigned>(n));
  std::normal_distribution<double> nd;
  std::bernoulli_distribution keep(0.25);
  // Φ = I + sparse off-diagonal terms, as the INS error model (60-80 % zeros).
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      if (i != j && keep(rng)) Phi(i, j) = 0.1 * nd(rng);
  const ErrorMatrix Qd = 1e-3 * random_spd(n, rng);
  const ErrorMatrix P0 = random_spd(n, rng);
  RowTransition<ins::kMaxErrorDim> Phi_rows;
  Phi_rows.assign(Phi);
  ErrorMatrix P = P0, tmp;
  fusion::covariance_predict(P, Phi_rows, Qd, tmp);
  const Eigen::MatrixXd expected = Phi * Eigen::MatrixXd(P0) * Phi.transpose() + Eigen::MatrixXd(Qd);
  EXPECT_LT(rel_diff(P, expected), 1e-14);
  EXPECT_EQ((P - P.transpose()).cwiseAbs().maxCoeff(), 0.0);
}

TEST_P(KalmanSizes, JosephUpdateEqualsTheTextbookFormAndIsSymmetric) {
  const int n = GetParam();
  std::mt19937 rng(11u + static_cast<unsigned>(n));
  std::normal_distribution<double> nd;
  const ErrorMatrix P0 = random_spd(n, rng);
  // A ZUPT + ZARU-like H: 6 rows over 9 of the n columns (velocity, attitude, gyro bias), other columns zero.
  H6 H = H6::Zero(6, n);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      H(i, 3 + j) = (i == j ? 1.0 : 0.0) + 0.05 * nd(rng);
      H(i, 6 + j) = 0.3 * nd(rng);
    }
    H(3 + i, 12 + i) = 1.0;
  }
  V6 r(6);
  for (int i = 0; i < 6; ++i) r(i) = nd(rng);
  R6 R = R6::Zero(6, 6);
  R.diagonal() << 4e-4, 4e-4, 4e-4, 1e-4, 1e-4, 1e-4;
  ErrorMatrix P = P0;
  ErrorVector dx;
  ASSERT_TRUE(fusion::joseph_update(P, H, r, R, dx));

  const Eigen::MatrixXd Pd = P0, Hd = H, Rd = R;
  const Eigen::MatrixXd K = Pd * Hd.transpose() * (Hd * Pd * Hd.transpose() + Rd).inverse();
  const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(n, n) - K * Hd;
  const Eigen::MatrixXd expected = IKH * Pd * IKH.transpose() + K * Rd * K.transpose();
  EXPECT_LT(rel_diff(P, expected), 1e-11);
  EXPECT_LT((dx - K * Eigen::VectorXd(r)).norm() / (K * Eigen::VectorXd(r)).norm(), 1e-11);
  EXPECT_EQ((P - P.transpose()).cwiseAbs().maxCoeff(), 0.0);
  // The update can only reduce the uncertainty: P0 − P is positive semi-definite.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Pd - Eigen::MatrixXd(P));
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-12);
}

// Consider states (Schmidt–Kalman, docs/error_state.md §5): the gain's rows of the consider block are zero, so those
// states are not corrected, and P is the Joseph covariance of that gain, (I − K_s H) P (I − K_s H)ᵀ + K_s R K_sᵀ —
// larger than the optimal update's, and the consider block's own variance unchanged.
TEST_P(KalmanSizes, ConsiderStatesAreNotCorrectedAndPIsTheJosephFormOfTheirGain) {
  const int n = GetParam();
  std::mt19937 rng(23u + static_cast<unsigned>(n));
  std::normal_distribution<double> nd;
  const ErrorMatrix P0 = random_spd(n, rng);
  H6 H = H6::Zero(6, n);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 9; ++j) H(i, 3 + j) = nd(rng);
  V6 r(6);
  for (int i = 0; i < 6; ++i) r(i) = nd(rng);
  R6 R = R6::Zero(6, 6);
  R.diagonal().setConstant(1e-2);
  const fusion::ConsiderStates consider{n - 9, 9};
  ErrorMatrix P = P0;
  ErrorVector dx;
  ASSERT_TRUE(fusion::joseph_update(P, H, r, R, dx, [](const auto&, const auto&) {}, consider));
  const Eigen::MatrixXd Pd = P0, Hd = H, Rd = R;
  Eigen::MatrixXd K = Pd * Hd.transpose() * (Hd * Pd * Hd.transpose() + Rd).inverse();
  const Eigen::MatrixXd K_opt = K;
  K.bottomRows(9).setZero();
  const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(n, n) - K * Hd;
  EXPECT_LT(rel_diff(P, IKH * Pd * IKH.transpose() + K * Rd * K.transpose()), 1e-11);
  EXPECT_TRUE(dx.tail(9).isZero(0.0));
  EXPECT_LT((dx - K * Eigen::VectorXd(r)).norm(), 1e-11 * (K * Eigen::VectorXd(r)).norm());
  EXPECT_LT(rel_diff(Eigen::MatrixXd(P).bottomRightCorner(9, 9), Pd.bottomRightCorner(9, 9)), 1e-12);
  // The optimal gain would have corrected them (the test is not vacuous), and P is at least the optimal P.
  EXPECT_GT(K_opt.bottomRows(9).norm(), 1e-3);
  const Eigen::MatrixXd IKH_opt = Eigen::MatrixXd::Identity(n, n) - K_opt * Hd;
  const Eigen::MatrixXd P_opt = IKH_opt * Pd * IKH_opt.transpose() + K_opt * Rd * K_opt.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(P) - P_opt);
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-12);
}

// gain_downdate with R = 0 and a gain K that belongs to another matrix (the filter's P), as the errors-in-variables
// footprints M use it (docs/consistency.md eq. E.3): M ← (I − K H) M (I − K H)ᵀ exactly, symmetric.
TEST_P(KalmanSizes, GainDowndateWithZeroNoiseIsTheTwoSidedProjection) {
  const int n = GetParam();
  std::mt19937 rng(13u + static_cast<unsigned>(n));
  std::normal_distribution<double> nd;
  const ErrorMatrix M0 = random_spd(n, rng);
  const Eigen::MatrixXd Kd = 0.2 * Eigen::MatrixXd::NullaryExpr(n, 3, [&]() { return nd(rng); });
  Eigen::MatrixXd Hd = Eigen::MatrixXd::Zero(3, n);
  for (int i = 0; i < 3; ++i) Hd(i, 3 + i) = 1.0, Hd(i, 6 + (i + 1) % 3) = 0.4 * nd(rng);
  using U3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::ColMajor, ins::kMaxErrorDim, 3>;
  const Eigen::MatrixXd Md = M0;
  const U3 U = Md * Hd.transpose();
  const Eigen::Matrix3d B = Hd * Md * Hd.transpose();
  const U3 K = Kd;
  ErrorMatrix M = M0;
  fusion::gain_downdate(M, U, K, B);
  const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(n, n) - Kd * Hd;
  EXPECT_LT(rel_diff(M, IKH * Md * IKH.transpose()), 1e-12);
  EXPECT_EQ((M - M.transpose()).cwiseAbs().maxCoeff(), 0.0);
}

TEST(Kalman, JosephUpdateRefusesANonPositiveInnovationCovariance) {
  const int n = 17;
  std::mt19937 rng(3u);
  const ErrorMatrix P0 = random_spd(n, rng);
  H6 H = H6::Zero(1, n);
  H(0, 3) = 1.0;
  V6 r = V6::Constant(1, 0.1);
  R6 R = R6::Constant(1, 1, -10.0);  // S = P33 − 10 < 0
  ErrorMatrix P = P0;
  ErrorVector dx = ErrorVector::Zero(n);
  EXPECT_FALSE(fusion::joseph_update(P, H, r, R, dx));
  EXPECT_EQ((P - P0).cwiseAbs().maxCoeff(), 0.0);  // P untouched
}

// 17: 15 INS states + clock + drift (white code); 29: + 12 code-multipath states (the default); 40: the capacity.
INSTANTIATE_TEST_SUITE_P(ErrorStateSizes, KalmanSizes, ::testing::Values(17, 29, 40));

}  // namespace
}  // namespace pednav
