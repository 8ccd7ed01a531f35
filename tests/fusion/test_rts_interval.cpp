// SPDX-License-Identifier: BSD-2-Clause
// RTS core (fusion/rts.*): the engine's interval bookkeeping (RtsInterval, docs/fusion.md eqs. 12.14-12.20) against
// the per-step composition on a random problem with everything the engine does inside a step (sequential updates,
// form-D re-expressions, clock/drift resets), the feedback deviation and the regressed shift of the interval records,
// and a reset folded into a step's transition (docs/fusion.md §12). The linear-Gaussian oracle: test_rts.cpp.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "fusion/rts.hpp"
#include "tests/support/random_matrix.hpp"

namespace pednav {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

using test::random_spd;


// Everything the engine does inside a mechanization step (docs/fusion.md §12.1, §12.4), on a random 9-state problem:
// a dense random transition per step; ZUPT-like updates (rows without clock and drift columns), each followed by a
// form-D-like re-expression δx_new = J δx_old, J = I + E_v B E_φᵀ, half of the time; clock and drift resets (fresh
// variables); GNSS-like updates that see every state, after the resets. One filter run feeds both bookkeepings; the
// records (M, m, S) and the smoothed errors and covariances must agree. Errors are measured in units of the smoothed
// σ (D = diag(P_s)^½ at each end of a record: |D_a⁻¹ ΔM D_b|, |D_a⁻¹ Δm|, |D_a⁻¹ ΔS D_a⁻¹|), so the unit-scale states
// are not hidden behind the clock's variance of 1e4.
constexpr int kNe = 9;  // 0-2 "velocity", 3-5 "attitude", 6 "bias", 7 "clock", 8 "drift"
constexpr int kVelE = 0, kAttE = 3, kClockE = 7, kDriftE = 8;
constexpr int kStepsE = 150;
constexpr double kTolRel = 1e-9;  // [smoothed σ] interval bookkeeping vs per-step composition

TEST(RtsInterval, EqualsPerStepCompositionWithReexpressionsAndResets) {
  std::mt19937 rng(20240917u);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const int n = kNe;
  const MatrixXd I = MatrixXd::Identity(n, n);
  auto randn = [&](int rows, int cols) {
    MatrixXd M(rows, cols);
    for (int j = 0; j < cols; ++j) {
      for (int i = 0; i < rows; ++i) M(i, j) = nd(rng);
    }
    return M;
  };
  MatrixXd P = random_spd(rng, n, 1.0);
  P(kClockE, kClockE) += 1e4;  // an unconverged clock next to unit-scale states (the solves are Jacobi-scaled)
  fusion::RtsAccumulator acc(n);
  fusion::RtsInterval interval(n);
  std::vector<fusion::RtsSegment> ref_segments, new_segments;
  std::vector<MatrixXd> filtered_P;
  bool open = false;
  int n_updates = 0, n_reexpressions = 0, n_resets = 0, n_reset_after_update = 0;
  // Joseph update of the filter with a residual drawn with the innovation covariance; the interval sees the same S
  // and K. Returns the correction fed back into the nominal (closed loop).
  auto kalman = [&](const MatrixXd& H) -> VectorXd {
    const int m = static_cast<int>(H.rows());
    const MatrixXd R = random_spd(rng, m, 0.1);
    const MatrixXd S = H * P * H.transpose() + R;
    const Eigen::LDLT<MatrixXd> ldlt(S);
    const MatrixXd K = ldlt.solve(H * P).transpose();
    const VectorXd r = Eigen::LLT<MatrixXd>(S).matrixL() * randn(m, 1);
    if (open) interval.update(H, r, ldlt, K);
    const MatrixXd IKH = I - K * H;
    P = IKH * P * IKH.transpose() + K * R * K.transpose();
    ++n_updates;
    return K * r;
  };
  for (int k = 0; k < kStepsE; ++k) {
    MatrixXd Phi = I + 0.05 * randn(n, n);
    Phi(kClockE, kDriftE) = 0.05;
    const MatrixXd Qd = random_spd(rng, n, 1e-3);
    const MatrixXd P_post = P;
    P = Phi * P * Phi.transpose() + Qd;
    if (open) interval.predict(Phi);
    // Reference quantities of this step (eqs. 12.1-12.3, 12.11): prior, δx⁻ = A δx + d, resets folded in.
    MatrixXd Phi_ref = Phi, P_prior = P, A = I;
    VectorXd d = VectorXd::Zero(n);
    bool updated = false;
    if (uni(rng) < 0.6) {
      MatrixXd H = randn(3, n);
      H.col(kClockE).setZero();
      H.col(kDriftE).setZero();
      d += A * kalman(H);
      updated = true;
      if (uni(rng) < 0.5) {
        const Eigen::Matrix3d B = 0.3 * randn(3, 3);
        MatrixXd J = I;
        J.block<3, 3>(kVelE, kAttE) = B;
        P = J * P * J.transpose();
        A.middleCols<3>(kAttE) -= A.middleCols<3>(kVelE) * B;  // A ← A J⁻¹, J⁻¹ = I − E_v B E_φᵀ (eq. 12.3)
        if (open) interval.reexpress(kVelE, kAttE, B);
        ++n_reexpressions;
      }
    }
    if (uni(rng) < 0.15) {
      const int i = uni(rng) < 0.5 ? kClockE : kDriftE;
      const double var = i == kClockE ? 900.0 : 1.0;
      P.row(i).setZero();
      P.col(i).setZero();
      P(i, i) = var;
      Phi_ref.row(i).setZero();
      P_prior.row(i).setZero();
      P_prior.col(i).setZero();
      P_prior(i, i) = var;
      d(i) = 0.0;
      if (open) interval.restart_state(i);
      ++n_resets;
      if (updated) ++n_reset_after_update;
    }
    if (uni(rng) < 0.3) d += A * kalman(randn(4, n));
    if (open) acc.append(fusion::rts_step(P_post, Phi_ref, P_prior, A, d));
    if ((k + 1) % 9 == 4) {  // output epochs: steps 4, 13, 22, ...
      if (open) {
        ref_segments.push_back(acc.take());
        new_segments.emplace_back();
        interval.close(P, new_segments.back());
      }
      interval.restart(P);
      open = true;
      filtered_P.push_back(P);
    }
  }
  ASSERT_GT(n_reexpressions, 10);
  ASSERT_GT(n_reset_after_update, 3);
  ASSERT_GT(n_resets, n_reset_after_update);
  const fusion::RtsSegment ref_tail = acc.take();
  fusion::RtsSegment new_tail;
  interval.close(P, new_tail);
  const std::vector<fusion::RtsSmoothed> ref = fusion::rts_backward(ref_segments, ref_tail, P);
  const std::vector<fusion::RtsSmoothed> got = fusion::rts_backward(new_segments, new_tail, P);
  ASSERT_EQ(ref.size(), filtered_P.size());
  ASSERT_EQ(got.size(), ref.size());
  auto sigma_inv = [](const MatrixXd& Ps) -> VectorXd { return Ps.diagonal().cwiseSqrt().cwiseInverse(); };
  double worst_M = 0, worst_m = 0, worst_S = 0, worst_dx = 0, worst_P = 0, smoothing = 0;
  for (size_t i = 0; i <= ref_segments.size(); ++i) {
    const bool tail = i == ref_segments.size();
    const fusion::RtsSegment& a = tail ? ref_tail : ref_segments[i];
    const fusion::RtsSegment& b = tail ? new_tail : new_segments[i];
    const VectorXd Da = sigma_inv(ref[i].P);
    const VectorXd Db_inv = (tail ? P : ref[i + 1].P).diagonal().cwiseSqrt();
    worst_M = std::max(worst_M, (Da.asDiagonal() * (b.M - a.M) * Db_inv.asDiagonal()).cwiseAbs().maxCoeff());
    worst_m = std::max(worst_m, (Da.asDiagonal() * (b.m - a.m)).cwiseAbs().maxCoeff());
    worst_S = std::max(worst_S, (Da.asDiagonal() * (b.S - a.S) * Da.asDiagonal()).cwiseAbs().maxCoeff());
    worst_dx = std::max(worst_dx, (Da.asDiagonal() * (got[i].dx - ref[i].dx)).cwiseAbs().maxCoeff());
    worst_P = std::max(worst_P, (Da.asDiagonal() * (got[i].P - ref[i].P) * Da.asDiagonal()).cwiseAbs().maxCoeff());
    smoothing = std::max(smoothing, (sigma_inv(filtered_P[i]).asDiagonal() * ref[i].dx).cwiseAbs().maxCoeff());
    for (int j = 0; j < n; ++j) {
      EXPECT_LE(got[i].P(j, j), filtered_P[i](j, j) * (1.0 + kTolRel)) << "output " << i << " state " << j;
    }
  }
  EXPECT_LT(worst_M, kTolRel);
  EXPECT_LT(worst_m, kTolRel);
  EXPECT_LT(worst_S, kTolRel);
  EXPECT_LT(worst_dx, kTolRel);
  EXPECT_LT(worst_P, kTolRel);
  // The smoothed errors are not small against the filtered σ (otherwise agreeing means would prove nothing).
  EXPECT_GT(smoothing, 0.1);
  std::printf("[ rts ] interval vs per-step, %zu records, %d updates, %d re-expressions, %d resets (%d after an "
              "update in the same step): max error [σ] M %.1e m %.1e S %.1e, smoothed dx %.1e P %.1e (|dx| up to "
              "%.2f filtered σ)\n",
              ref.size(), n_updates, n_reexpressions, n_resets, n_reset_after_update, worst_M, worst_m, worst_S,
              worst_dx, worst_P, smoothing);
}

// A feedback that is not K r (the errors-in-variables compensation of the scale-factor updates subtracts a bias from
// the correction of a constant state, docs/consistency.md eq. E.4): the per-step reference takes d = the correction
// actually fed back, and the interval bookkeeping is told the deviation with shift_mean (eq. E.6). For a state without
// process noise the smoothed estimate of that state (nominal + smoothed error) is one constant over the run, and both
// formulations give it; without shift_mean the interval one drifts back by the deviations (what the engine's smoother
// did before eq. E.6 went in, 2026-12-03).
TEST(RtsInterval, FeedbackDeviationOnAConstantStateKeepsItsSmoothedValueConstant) {
  std::mt19937 rng(20261202u);
  std::normal_distribution<double> nd(0.0, 1.0);
  constexpr int n = 6, kConst = 5, kSteps = 120, kEvery = 7;
  const MatrixXd I = MatrixXd::Identity(n, n);
  MatrixXd P = random_spd(rng, n, 1.0);
  VectorXd nominal = VectorXd::Zero(n);  // the closed-loop nominal of the constant state is what is compared
  fusion::RtsAccumulator acc(n);
  fusion::RtsInterval shifted(n), plain(n);
  std::vector<fusion::RtsSegment> ref_seg, shifted_seg, plain_seg;
  std::vector<double> nominal_at_output;
  bool open = false;
  double deviation_total = 0.0;
  for (int k = 0; k < kSteps; ++k) {
    MatrixXd Phi = I;
    for (int i = 0; i < n - 1; ++i) {
      for (int j = 0; j < n; ++j) Phi(i, j) += 0.05 * nd(rng);
    }
    MatrixXd Qd = random_spd(rng, n, 1e-3);
    Qd.row(kConst).setZero();
    Qd.col(kConst).setZero();
    const MatrixXd P_post = P;
    P = Phi * P * Phi.transpose() + Qd;
    if (open) {
      shifted.predict(Phi);
      plain.predict(Phi);
    }
    const MatrixXd P_prior = P;
    VectorXd d = VectorXd::Zero(n);
    MatrixXd H(2, n);
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < n; ++j) H(i, j) = nd(rng);
    }
    H.col(kConst).setZero();  // as for a scale factor: no measurement sees it directly
    const MatrixXd R = random_spd(rng, 2, 0.1);
    const MatrixXd S = H * P * H.transpose() + R;
    const Eigen::LDLT<MatrixXd> ldlt(S);
    const MatrixXd K = ldlt.solve(H * P).transpose();
    const VectorXd r = Eigen::LLT<MatrixXd>(S).matrixL() * VectorXd::NullaryExpr(2, [&] { return nd(rng); });
    if (open) {
      shifted.update(H, r, ldlt, K);
      plain.update(H, r, ldlt, K);
    }
    VectorXd dx = K * r;
    const double deviation = 0.02 * std::sqrt(P(kConst, kConst)) * (1.0 + 0.5 * nd(rng));  // a bias, one sign
    dx(kConst) -= deviation;
    if (open) shifted.shift_mean(kConst, -deviation);
    if (open) deviation_total += deviation;
    nominal += dx;
    d += dx;
    const MatrixXd IKH = I - K * H;
    P = IKH * P * IKH.transpose() + K * R * K.transpose();
    if (open) acc.append(fusion::rts_step(P_post, Phi, P_prior, I, d));
    if ((k + 1) % kEvery == 0) {
      if (open) {
        ref_seg.push_back(acc.take());
        shifted_seg.emplace_back();
        shifted.close(P, shifted_seg.back());
        plain_seg.emplace_back();
        plain.close(P, plain_seg.back());
      }
      shifted.restart(P);
      plain.restart(P);
      open = true;
      nominal_at_output.push_back(nominal(kConst));
    }
  }
  auto tail = [&](fusion::RtsInterval& iv) {
    fusion::RtsSegment t;
    iv.close(P, t);
    return t;
  };
  const auto ref = fusion::rts_backward(ref_seg, acc.take(), P);
  const auto got = fusion::rts_backward(shifted_seg, tail(shifted), P);
  const auto old = fusion::rts_backward(plain_seg, tail(plain), P);
  ASSERT_EQ(ref.size(), nominal_at_output.size());
  const double sigma = std::sqrt(P(kConst, kConst));
  const double final_value = nominal_at_output.back() + ref.back().dx(kConst);
  double worst_ref = 0.0, worst_got = 0.0, worst_old = 0.0;
  for (size_t i = 0; i < ref.size(); ++i) {
    worst_ref = std::max(worst_ref, std::abs(nominal_at_output[i] + ref[i].dx(kConst) - final_value) / sigma);
    worst_got = std::max(worst_got, std::abs(nominal_at_output[i] + got[i].dx(kConst) - final_value) / sigma);
    worst_old = std::max(worst_old, std::abs(nominal_at_output[i] + old[i].dx(kConst) - final_value) / sigma);
  }
  std::printf("[ rts ] constant state, %zu outputs, deviations %.2f final σ in all: smoothed value off its final one by "
              "%.1e σ (reference), %.1e σ (shift_mean), %.2f σ (without)\n",
              ref.size(), deviation_total / sigma, worst_ref, worst_got, worst_old);
  EXPECT_LT(worst_ref, kTolRel);
  EXPECT_LT(worst_got, kTolRel);
  EXPECT_GT(worst_old, 0.5);  // the defect is visible without the shift, else the test proves nothing
}

// shift_mean_regressed (docs/consistency.md eq. E.7): μ moves by Γ_{:,S} P_SS⁻¹ δ; in the row of a constant state
// (Γ's row = P's row) that is δ itself, as shift_mean (eq. E.6) does.
TEST(RtsInterval, RegressedShiftMovesEveryComponentAndTheConstantRowsByDelta) {
  std::mt19937 rng(4u);
  std::normal_distribution<double> nd(0.0, 1.0);
  constexpr int n = 6;
  const int states[2] = {4, 5};
  const double delta[2] = {0.3, -0.2};
  MatrixXd P = random_spd(rng, n, 1.0);
  fusion::RtsInterval iv(n);
  iv.restart(P);
  for (int k = 0; k < 5; ++k) {  // a few steps so that Γ differs from P in the non-constant rows
    MatrixXd Phi = MatrixXd::Identity(n, n);
    for (int i = 0; i < n - 2; ++i) {
      for (int j = 0; j < n; ++j) Phi(i, j) += 0.1 * nd(rng);
    }
    MatrixXd Qd = random_spd(rng, n, 0.01);
    Qd.bottomRows(2).setZero();
    Qd.rightCols(2).setZero();
    P = Phi * P * Phi.transpose() + Qd;
    iv.predict(Phi);
    MatrixXd H = MatrixXd::Zero(1, n);
    for (int j = 0; j < n - 2; ++j) H(0, j) = nd(rng);
    const MatrixXd S = H * P * H.transpose() + MatrixXd::Identity(1, 1) * 0.1;
    const Eigen::LDLT<MatrixXd> ldlt(S);
    const MatrixXd K = ldlt.solve(H * P).transpose();
    iv.update(H, VectorXd::Constant(1, nd(rng)), ldlt, K);
    P = (MatrixXd::Identity(n, n) - K * H) * P;
    P = 0.5 * (P + P.transpose()).eval();
  }
  const VectorXd mu0 = iv.mean();
  const MatrixXd Gamma = iv.cross();
  iv.shift_mean_regressed(states, delta, 2, P);
  Eigen::Matrix2d P_SS;
  P_SS << P(4, 4), P(4, 5), P(5, 4), P(5, 5);
  const Eigen::Vector2d y = P_SS.llt().solve(Eigen::Vector2d(delta[0], delta[1]));
  const VectorXd expected = mu0 + Gamma.col(4) * y(0) + Gamma.col(5) * y(1);
  EXPECT_LT((iv.mean() - expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(iv.mean()(4) - mu0(4), delta[0], 1e-9);
  EXPECT_NEAR(iv.mean()(5) - mu0(5), delta[1], 1e-9);
  EXPECT_GT((iv.mean() - mu0).head(n - 2).cwiseAbs().maxCoeff(), 1e-3);  // the other components move too
}

TEST(RtsStep, ResetFoldedIntoTransitionDecouplesTheState) {
  // A state reset (fresh variable, docs/fusion.md eq. 12.11) is a transition row of zeros: the smoothed error
  // before the reset is then the regression of that state on the others, and a later correction of the reset
  // state itself does not reach back.
  std::mt19937 rng(7u);
  const MatrixXd P = random_spd(rng, 3, 1.0);
  MatrixXd Phi = MatrixXd::Identity(3, 3);
  Phi.row(2).setZero();
  MatrixXd Pp = Phi * P * Phi.transpose();
  Pp(2, 2) = 900.0;
  const fusion::RtsStep s =
      fusion::rts_step(P, Phi, Pp, MatrixXd::Identity(3, 3), VectorXd::Zero(3));
  VectorXd next(3);
  next << 0.0, 0.0, 5.0;
  EXPECT_LT((s.G * next).norm(), 1e-12);  // a correction of the fresh state says nothing about the old one
  next << 0.1, -0.2, 0.0;
  const VectorXd prev = s.G * next;
  EXPECT_NEAR(prev(0), 0.1, 1e-12);
  EXPECT_NEAR(prev(1), -0.2, 1e-12);
  const VectorXd reg = P.block(2, 0, 1, 2) * P.topLeftCorner(2, 2).inverse() * next.head(2);
  EXPECT_NEAR(prev(2), reg(0), 1e-12);
}

}  // namespace
}  // namespace pednav
