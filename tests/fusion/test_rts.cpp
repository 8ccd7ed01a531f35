// RTS core (fusion/rts.*) on a linear-Gaussian problem: a closed-loop Kalman filter (nominal corrected after each
// update, error estimate reset to zero) feeding the same accumulator/backward pass as the engine must reproduce
// the batch weighted least-squares solution of the whole problem (states and their covariances) — issue 6's
// oracle. docs/fusion.md §12.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "fusion/rts.hpp"

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

MatrixXd random_spd(std::mt19937& rng, int n, double scale) {
  std::normal_distribution<double> nd(0.0, 1.0);
  MatrixXd L(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) L(i, j) = nd(rng);
  }
  return scale * (L * L.transpose() / n + 0.2 * MatrixXd::Identity(n, n));
}

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
  std::vector<fusion::RtsSmoothed> smoothed;
};

// Closed-loop KF in the engine's order: predict, sequential updates (nominal corrected, error reset), record the
// step, output every `every` steps from `first_output` on.
SmootherRun run_closed_loop(const Problem& p, int first_output, int every) {
  SmootherRun out;
  VectorXd x = p.m0;
  MatrixXd P = p.P0;
  fusion::RtsAccumulator acc(kN);
  std::vector<fusion::RtsSegment> segments;
  bool open = false;
  for (int k = 0; k < kSteps; ++k) {
    const MatrixXd P_post = P;
    x = p.Phi * x;
    P = p.Phi * P * p.Phi.transpose() + p.Q;
    const MatrixXd P_prior = P;
    const MatrixXd A = MatrixXd::Identity(kN, kN);
    VectorXd d = VectorXd::Zero(kN);
    for (const Meas& m : p.meas) {
      if (m.step != k + 1) continue;
      const MatrixXd S = m.H * P * m.H.transpose() + m.R;
      const MatrixXd K = P * m.H.transpose() * S.inverse();
      const VectorXd dx = K * (m.y - m.H * x);
      const MatrixXd IKH = MatrixXd::Identity(kN, kN) - K * m.H;
      P = IKH * P * IKH.transpose() + K * m.R * K.transpose();
      x += dx;     // closed loop: the nominal takes the correction, the error estimate is zero again
      d += A * dx;
    }
    if (open) acc.append(fusion::rts_step(P_post, p.Phi, P_prior, A, d));
    const int step = k + 1;
    if (step >= first_output && (step - first_output) % every == 0) {
      if (open) segments.push_back(acc.take());
      open = true;
      out.output_steps.push_back(step);
      out.filtered.push_back(x);
      out.filtered_P.push_back(P);
    }
  }
  out.smoothed = fusion::rts_backward(segments, acc.take(), P);
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
  double worst_x = 0, worst_P = 0, worst_fwd = 0;
  for (size_t i = 0; i < r.output_steps.size(); ++i) {
    const int k = r.output_steps[i];
    const VectorXd xs = r.filtered[i] + r.smoothed[i].dx;  // nominal ⊞ smoothed error (linear: +)
    worst_x = std::max(worst_x, (xs - X.segment(k * kN, kN)).cwiseAbs().maxCoeff());
    worst_P = std::max(worst_P, (r.smoothed[i].P - cov.block(k * kN, k * kN, kN, kN)).cwiseAbs().maxCoeff());
    worst_fwd = std::max(worst_fwd, (r.filtered[i] - X.segment(k * kN, kN)).cwiseAbs().maxCoeff());
    for (int j = 0; j < kN; ++j) {
      EXPECT_LE(r.smoothed[i].P(j, j), r.filtered_P[i](j, j) + kTolSigmaOrder) << "step " << k << " state " << j;
    }
  }
  EXPECT_LT(worst_x, kTolState);
  EXPECT_LT(worst_P, kTolCov);
  // The filter alone is not the batch solution (otherwise the test could not fail).
  EXPECT_GT(worst_fwd, 1e3 * kTolState);
  std::printf("[ rts ] outputs every %d steps from %d: max |x_s − x_WLS| %.2e, max |P_s − P_WLS| %.2e "
              "(forward vs WLS %.2e)\n",
              every, first_output, worst_x, worst_P, worst_fwd);
}

// Every step an output (no composition), outputs every 3 steps from step 2 (steps before the first output and
// after the last one are composed into the tail), and a single long segment.
INSTANTIATE_TEST_SUITE_P(Decimation, RtsLinearGaussian,
                         ::testing::Values(std::pair{1, 1}, std::pair{2, 3}, std::pair{1, 13}));

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
