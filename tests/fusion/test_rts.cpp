// SPDX-License-Identifier: BSD-2-Clause
// RTS core (fusion/rts.*) on a linear-Gaussian problem: a closed-loop Kalman filter (nominal corrected after each
// update, error estimate reset to zero) feeding the interval bookkeeping of the engine (RtsInterval, docs/fusion.md
// eqs. 12.14-12.20) and, as the reference, the per-step backward maps (rts_step + RtsAccumulator, eqs. 12.1-12.11),
// then the same backward pass, must reproduce the batch weighted least-squares solution of the whole problem (states
// and their covariances) — issue 6's oracle; the same with consider (Schmidt) states. The interval bookkeeping against
// the per-step composition with everything the engine does inside a step: test_rts_interval.cpp. docs/fusion.md §12.
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

constexpr int kN = 4;                 // state: 2D position + velocity
constexpr int kSteps = 40;            // transitions
constexpr double kDt_s = 0.1;
constexpr double kTolState = 1e-9;    // [state units] smoothed mean vs batch WLS (issue 6)
constexpr double kTolCov = 1e-9;      // [state units²] smoothed covariance vs batch WLS
constexpr double kTolSigmaOrder = 1e-12;  // [state units²] smoothed variance may not exceed the filtered one

using test::random_spd;

struct Meas {
  int step;
  MatrixXd H;
  VectorXd y;
  MatrixXd R;
};

struct Problem {
  MatrixXd Phi, Q, P0;
  VectorXd m0;
  std::vector<Meas> meas;  // several per step allowed (sequential updates within the step)
};

Problem make_problem(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  Problem p;
  p.Phi = MatrixXd::Identity(kN, kN);
  p.Phi(0, 1) = kDt_s;
  p.Phi(2, 3) = kDt_s;
  p.Phi(1, 3) = 0.02;  // a little coupling so that nothing is block-diagonal
  p.Phi(3, 0) = -0.01;
  p.Q = random_spd(rng, kN, 0.01);
  p.P0 = random_spd(rng, kN, 4.0);
  p.m0 = VectorXd::Zero(kN);
  for (int i = 0; i < kN; ++i) p.m0(i) = nd(rng);
  // Truth to generate measurements from.
  Eigen::LLT<MatrixXd> lq(p.Q), lp(p.P0);
  VectorXd x = p.m0;
  VectorXd z(kN);
  for (int i = 0; i < kN; ++i) z(i) = nd(rng);
  x += lp.matrixL() * z;
  for (int k = 1; k <= kSteps; ++k) {
    for (int i = 0; i < kN; ++i) z(i) = nd(rng);
    x = p.Phi * x + lq.matrixL() * z;
    // Position fix every 5th step, a velocity-like measurement (2 rows) every 2nd step, none otherwise:
    // steps with 0, 1 and 2 sequential updates.
    if (k % 5 == 0) {
      Meas m{k, MatrixXd::Zero(2, kN), VectorXd(2), random_spd(rng, 2, 0.5)};
      m.H(0, 0) = 1.0;
      m.H(1, 2) = 1.0;
      m.H(1, 0) = 0.3;
      m.y = m.H * x + Eigen::LLT<MatrixXd>(m.R).matrixL() * VectorXd::NullaryExpr(2, [&]() { return nd(rng); });
      p.meas.push_back(m);
    }
    if (k % 2 == 0) {
      Meas m{k, MatrixXd::Zero(1, kN), VectorXd(1), MatrixXd::Constant(1, 1, 0.05)};
      m.H(0, 1) = 1.0;
      m.H(0, 3) = -0.5;
      m.y = m.H * x + VectorXd::Constant(1, std::sqrt(0.05) * nd(rng));
      p.meas.push_back(m);
    }
  }
  return p;
}

// Batch WLS over all states x_0..x_N: min |x_0 − m0|²_{P0⁻¹} + Σ|x_{k+1} − Φ x_k|²_{Q⁻¹} + Σ|y − H x_k|²_{R⁻¹}.
// Returns the stacked solution and the inverse normal matrix (covariance).
std::pair<VectorXd, MatrixXd> batch_wls(const Problem& p) {
  const int dim = (kSteps + 1) * kN;
  MatrixXd Lambda = MatrixXd::Zero(dim, dim);
  VectorXd b = VectorXd::Zero(dim);
  const MatrixXd P0i = p.P0.inverse(), Qi = p.Q.inverse();
  Lambda.block(0, 0, kN, kN) += P0i;
  b.segment(0, kN) += P0i * p.m0;
  for (int k = 0; k < kSteps; ++k) {
    // r = x_{k+1} − Φ x_k = E x with E = [−Φ  I] on (x_k, x_{k+1}).
    MatrixXd E(kN, 2 * kN);
    E << -p.Phi, MatrixXd::Identity(kN, kN);
    Lambda.block(k * kN, k * kN, 2 * kN, 2 * kN) += E.transpose() * Qi * E;
  }
  for (const Meas& m : p.meas) {
    const MatrixXd Ri = m.R.inverse();
    Lambda.block(m.step * kN, m.step * kN, kN, kN) += m.H.transpose() * Ri * m.H;
    b.segment(m.step * kN, kN) += m.H.transpose() * Ri * m.y;
  }
  const MatrixXd cov = Lambda.ldlt().solve(MatrixXd::Identity(dim, dim));
  return {cov * b, cov};
}

struct SmootherRun {
  std::vector<int> output_steps;
  std::vector<VectorXd> filtered;     // nominal (= filtered mean) at the outputs
  std::vector<MatrixXd> filtered_P;
  std::vector<fusion::RtsSmoothed> smoothed;      // per-step composition (reference)
  std::vector<fusion::RtsSmoothed> smoothed_new;  // interval bookkeeping (the engine's)
};

// Closed-loop KF in the engine's order: predict, sequential updates (nominal corrected, error reset), record the
// step, output every `every` steps from `first_output` on.
SmootherRun run_closed_loop(const Problem& p, int first_output, int every) {
  SmootherRun out;
  VectorXd x = p.m0;
  MatrixXd P = p.P0;
  fusion::RtsAccumulator acc(kN);
  fusion::RtsInterval interval(kN);
  std::vector<fusion::RtsSegment> segments, segments_new;
  bool open = false;
  for (int k = 0; k < kSteps; ++k) {
    const MatrixXd P_post = P;
    x = p.Phi * x;
    P = p.Phi * P * p.Phi.transpose() + p.Q;
    interval.predict(p.Phi);
    const MatrixXd P_prior = P;
    const MatrixXd A = MatrixXd::Identity(kN, kN);
    VectorXd d = VectorXd::Zero(kN);
    for (const Meas& m : p.meas) {
      if (m.step != k + 1) continue;
      const MatrixXd S = m.H * P * m.H.transpose() + m.R;
      const MatrixXd K = P * m.H.transpose() * S.inverse();
      const VectorXd r = m.y - m.H * x;
      const VectorXd dx = K * r;
      interval.update(m.H, r, Eigen::LDLT<MatrixXd>(S), K);
      const MatrixXd IKH = MatrixXd::Identity(kN, kN) - K * m.H;
      P = IKH * P * IKH.transpose() + K * m.R * K.transpose();
      x += dx;     // closed loop: the nominal takes the correction, the error estimate is zero again
      d += A * dx;
    }
    if (open) acc.append(fusion::rts_step(P_post, p.Phi, P_prior, A, d));
    const int step = k + 1;
    if (step >= first_output && (step - first_output) % every == 0) {
      if (open) {
        segments.push_back(acc.take());
        segments_new.emplace_back();
        interval.close(P, segments_new.back());
      }
      interval.restart(P);
      open = true;
      out.output_steps.push_back(step);
      out.filtered.push_back(x);
      out.filtered_P.push_back(P);
    }
  }
  out.smoothed = fusion::rts_backward(segments, acc.take(), P);
  fusion::RtsSegment tail;
  interval.close(P, tail);
  out.smoothed_new = fusion::rts_backward(segments_new, tail, P);
  return out;
}

class RtsLinearGaussian : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(RtsLinearGaussian, EqualsBatchWeightedLeastSquares) {
  const auto [first_output, every] = GetParam();
  const Problem p = make_problem(20240606u);
  const auto [X, cov] = batch_wls(p);
  const SmootherRun r = run_closed_loop(p, first_output, every);
  ASSERT_EQ(r.smoothed.size(), r.output_steps.size());
  ASSERT_GE(r.output_steps.size(), 3u);
  ASSERT_EQ(r.smoothed_new.size(), r.output_steps.size());
  double worst_x = 0, worst_P = 0, worst_fwd = 0, worst_x_new = 0, worst_P_new = 0;
  for (size_t i = 0; i < r.output_steps.size(); ++i) {
    const int k = r.output_steps[i];
    const VectorXd xs = r.filtered[i] + r.smoothed[i].dx;  // nominal ⊞ smoothed error (linear: +)
    worst_x = std::max(worst_x, (xs - X.segment(k * kN, kN)).cwiseAbs().maxCoeff());
    worst_P = std::max(worst_P, (r.smoothed[i].P - cov.block(k * kN, k * kN, kN, kN)).cwiseAbs().maxCoeff());
    const VectorXd xs_new = r.filtered[i] + r.smoothed_new[i].dx;
    worst_x_new = std::max(worst_x_new, (xs_new - X.segment(k * kN, kN)).cwiseAbs().maxCoeff());
    worst_P_new =
        std::max(worst_P_new, (r.smoothed_new[i].P - cov.block(k * kN, k * kN, kN, kN)).cwiseAbs().maxCoeff());
    worst_fwd = std::max(worst_fwd, (r.filtered[i] - X.segment(k * kN, kN)).cwiseAbs().maxCoeff());
    for (int j = 0; j < kN; ++j) {
      EXPECT_LE(r.smoothed[i].P(j, j), r.filtered_P[i](j, j) + kTolSigmaOrder) << "step " << k << " state " << j;
      EXPECT_LE(r.smoothed_new[i].P(j, j), r.filtered_P[i](j, j) + kTolSigmaOrder) << "step " << k << " state " << j;
    }
  }
  EXPECT_LT(worst_x, kTolState);
  EXPECT_LT(worst_P, kTolCov);
  EXPECT_LT(worst_x_new, kTolState);
  EXPECT_LT(worst_P_new, kTolCov);
  // The filter alone is not the batch solution (otherwise the test could not fail).
  EXPECT_GT(worst_fwd, 1e3 * kTolState);
  std::printf("[ rts ] outputs every %d steps from %d: max |x_s − x_WLS| %.2e, max |P_s − P_WLS| %.2e "
              "(interval bookkeeping %.2e, %.2e; forward vs WLS %.2e)\n",
              every, first_output, worst_x, worst_P, worst_x_new, worst_P_new, worst_fwd);
}

// Every step an output (no composition), outputs every 3 steps from step 2 (steps before the first output and
// after the last one are composed into the tail), and a single long segment.
INSTANTIATE_TEST_SUITE_P(Decimation, RtsLinearGaussian,
                         ::testing::Values(std::pair{1, 1}, std::pair{2, 3}, std::pair{1, 13}));

// Consider states (docs/fusion.md §12.6): the forward filter is a Schmidt–Kalman filter (state 3's gain row zeroed,
// nominal never corrected there, P its exact Joseph covariance), so its error has a non-zero conditional mean. The
// smoother runs on the Kalman-gain filter of the same problem, kept as a mean η of the Schmidt filter's error and its
// covariance P_o (eqs. 12.21-12.25): Schmidt nominal + smoothed error must again be the batch WLS solution, and the
// records built from the Schmidt filter's own P, S and K (what the engine did before §12.6) must not be.
TEST(RtsConsiderStates, KalmanGainShadowOfASchmidtFilterEqualsBatchWeightedLeastSquares) {
  constexpr int kConsider = 3;
  const Problem p = make_problem(20240606u);
  const auto [X, cov] = batch_wls(p);
  for (const int every : {1, 3, 13}) {
    VectorXd x = p.m0;  // the Schmidt filter's nominal
    MatrixXd P = p.P0, Po = p.P0;
    VectorXd eta = VectorXd::Zero(kN);
    fusion::RtsInterval shadow(kN), naive(kN);
    std::vector<fusion::RtsSegment> seg_shadow, seg_naive;
    std::vector<int> outputs;
    std::vector<VectorXd> nominal;
    bool open = false;
    double worst_fwd_gap = 0.0;  // |Schmidt nominal − Kalman filter mean|: the consider state must matter
    for (int k = 0; k < kSteps; ++k) {
      x = p.Phi * x;
      P = p.Phi * P * p.Phi.transpose() + p.Q;
      Po = p.Phi * Po * p.Phi.transpose() + p.Q;
      eta = p.Phi * eta;  // eq. 12.22
      shadow.predict(p.Phi);
      naive.predict(p.Phi);
      for (const Meas& m : p.meas) {
        if (m.step != k + 1) continue;
        const VectorXd r = m.y - m.H * x;
        // Schmidt gain, exact (expanded Joseph) covariance.
        const MatrixXd S = m.H * P * m.H.transpose() + m.R;
        MatrixXd K = P * m.H.transpose() * S.inverse();
        K.row(kConsider).setZero();
        naive.update(m.H, r, Eigen::LDLT<MatrixXd>(S), K);
        const MatrixXd IKH = MatrixXd::Identity(kN, kN) - K * m.H;
        P = IKH * P * IKH.transpose() + K * m.R * K.transpose();
        // Kalman gain on the same residual, relative to the mean η of the Schmidt filter's error (eq. 12.23).
        const VectorXd nu = r - m.H * eta;
        const MatrixXd So = m.H * Po * m.H.transpose() + m.R;
        const MatrixXd Ko = Po * m.H.transpose() * So.inverse();
        shadow.update(m.H, nu, Eigen::LDLT<MatrixXd>(So), Ko);
        const MatrixXd IKHo = MatrixXd::Identity(kN, kN) - Ko * m.H;
        Po = IKHo * Po * IKHo.transpose() + Ko * m.R * Ko.transpose();
        eta += Ko * nu;
        const VectorXd dx = K * r;  // fed back into the Schmidt nominal
        x += dx;
        eta -= dx;
      }
      const int step = k + 1;
      if (step % every == 0) {
        if (open) {
          seg_shadow.emplace_back();
          shadow.close(Po, eta, seg_shadow.back());
          seg_naive.emplace_back();
          naive.close(P, seg_naive.back());
        }
        shadow.restart(Po, eta);
        naive.restart(P);
        open = true;
        outputs.push_back(step);
        nominal.push_back(x);
        worst_fwd_gap = std::max(worst_fwd_gap, eta.cwiseAbs().maxCoeff());
      }
    }
    fusion::RtsSegment tail_shadow, tail_naive;
    shadow.close(Po, eta, tail_shadow);
    naive.close(P, tail_naive);
    const auto sm = fusion::rts_backward(seg_shadow, tail_shadow, Po, eta);
    const auto sm_naive = fusion::rts_backward(seg_naive, tail_naive, P);
    ASSERT_EQ(sm.size(), outputs.size());
    double worst_x = 0, worst_P = 0, worst_naive = 0;
    for (size_t i = 0; i < outputs.size(); ++i) {
      const int k = outputs[i];
      worst_x = std::max(worst_x, (nominal[i] + sm[i].dx - X.segment(k * kN, kN)).cwiseAbs().maxCoeff());
      worst_P = std::max(worst_P, (sm[i].P - cov.block(k * kN, k * kN, kN, kN)).cwiseAbs().maxCoeff());
      worst_naive = std::max(worst_naive, (nominal[i] + sm_naive[i].dx - X.segment(k * kN, kN)).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst_x, kTolState) << "outputs every " << every;
    EXPECT_LT(worst_P, kTolCov) << "outputs every " << every;
    EXPECT_GT(worst_fwd_gap, 1e3 * kTolState);  // the Schmidt filter is not the Kalman filter
    EXPECT_GT(worst_naive, 1e3 * kTolState);    // nor is its RTS pass the smoother
    std::printf("[ rts consider ] every %d: max |x_s − x_WLS| %.2e, |P_s − P_WLS| %.2e; Schmidt vs Kalman mean %.2e, "
                "RTS on the Schmidt filter vs WLS %.2e\n",
                every, worst_x, worst_P, worst_fwd_gap, worst_naive);
  }
}

}  // namespace
}  // namespace pednav
