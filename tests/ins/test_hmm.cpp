// SPDX-License-Identifier: BSD-2-Clause
// Tests of ins/hmm.*: forward-backward and Viterbi against brute-force enumeration, Baum-Welch monotonicity and
// recovery of a known generator, observation extraction and the mapping of decoded states to samples.
#include "ins/hmm.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numeric>

namespace pednav::ins {
namespace {

using ::testing::HasSubstr;

// Seed 002's trained model (A printed after §3.4 and Table 2 [%]) as the generator of synthetic sequences. Rows
// are renormalized (the printed rows sum to 0.9998-1.0003).
HmmModel seed002_trained_model() {
  HmmModel m;
  m.A << 0, 0.9620, 0.0247, 0.0133,  //
      0.0110, 0.0310, 0.9253, 0.0326,  //
      0.0016, 0.0135, 0.0344, 0.9505,  //
      0.9717, 0.0115, 0.0166, 0;
  const double table2[kHmmSymbols][kHmmStates] = {
      {78.09, 0, 0, 0}, {16.98, 0, 0, 0},   {2.83, 0, 17.29, 0}, {0, 0, 46.63, 0}, {0, 0, 27.06, 0},
      {2.11, 0, 5.27, 0}, {0, 3.1, 0, 0},   {0, 0, 0, 38.95},    {0, 0, 0, 61.05}, {0, 0, 0.49, 0},
      {0, 3.75, 0, 0},  {0, 0, 3.26, 0},    {0, 16.15, 0, 0},    {0, 68.19, 0, 0}, {0, 8.81, 0, 0}};
  for (int j = 0; j < kHmmStates; ++j) {
    for (int k = 0; k < kHmmSymbols; ++k) m.B(j, k) = table2[k][j];
    m.B.row(j) /= m.B.row(j).sum();
    m.A.row(j) /= m.A.row(j).sum();
  }
  m.pi << 0.25, 0.25, 0.25, 0.25;
  return m;
}

// P(O | λ) by enumerating every state path (N^T terms).
double brute_force_likelihood(const HmmModel& m, const std::vector<int>& o, std::vector<int>* best_path) {
  const int T = static_cast<int>(o.size());
  int paths = 1;
  for (int t = 0; t < T; ++t) paths *= kHmmStates;
  double total = 0.0, best = -1.0;
  for (int code = 0; code < paths; ++code) {
    std::vector<int> q(T);
    int c = code;
    for (int t = 0; t < T; ++t) {
      q[t] = c % kHmmStates;
      c /= kHmmStates;
    }
    double p = m.pi(q[0]) * m.B(q[0], o[0]);
    for (int t = 1; t < T; ++t) p *= m.A(q[t - 1], q[t]) * m.B(q[t], o[t]);
    total += p;
    if (p > best) {
      best = p;
      if (best_path) *best_path = q;
    }
  }
  return total;
}

TEST(Hmm, InitialModelIsSeed002A1AndTable1) {
  const HmmModel m = seed002_initial_model(0.0);
  EXPECT_TRUE(m.problems().empty());
  EXPECT_DOUBLE_EQ(m.A(0, 1), 0.85);
  EXPECT_DOUBLE_EQ(m.A(3, 0), 0.85);
  EXPECT_DOUBLE_EQ(m.A(2, 2), 0.05);
  constexpr double kTol = 1e-12;
  // Table 1: state A emits grade 1 with 72.3 % (column sums 99.99 %), state D grade 9 with 60.6 % (99.97 %).
  EXPECT_NEAR(m.B(kPushOff, 0), 72.3 / 99.99, kTol);
  EXPECT_NEAR(m.B(kStance, 8), 60.6 / 99.97, kTol);
  EXPECT_EQ(m.B(kSwing, 2), 0.0);
  const HmmModel f = seed002_initial_model(1e-3);
  EXPECT_GT(f.B(kSwing, 2), 0.0);
  EXPECT_TRUE(f.problems().empty());
}

TEST(Hmm, ProblemsNameTheBadRow) {
  HmmModel m = seed002_initial_model();
  m.A(2, 0) = 0.5;
  m.B(1, 3) = -0.1;
  const auto p = m.problems();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_THAT(p[0], HasSubstr("A row 3 sums to"));
  EXPECT_THAT(p[1], HasSubstr("B row 2 has a negative"));
  HmmObservationOptions o;
  o.axis = 3;
  o.grade_width_radps = 0;
  const auto q = o.problems();
  ASSERT_EQ(q.size(), 2u);
  EXPECT_THAT(q[0], HasSubstr("axis must be x, y or z"));
  EXPECT_THAT(q[1], HasSubstr("grade width must be > 0"));
}

TEST(Hmm, ForwardBackwardAndViterbiMatchEnumeration) {
  const HmmModel m = seed002_initial_model(1e-3);
  const std::vector<int> o = {0, 13, 4, 8, 8, 0, 13};  // 4^7 = 16384 paths
  std::vector<int> best;
  const double p = brute_force_likelihood(m, o, &best);
  const ForwardBackward fb = forward_backward(m, o);
  constexpr double kTolLogLik = 1e-10;
  EXPECT_NEAR(fb.log_likelihood, std::log(p), kTolLogLik);
  EXPECT_EQ(viterbi(m, o), best);
  // γ_t sums to 1 at every t.
  for (const auto& g : fb.gamma) EXPECT_NEAR(g.sum(), 1.0, 1e-12);
  // Impossible symbol: -inf, empty Viterbi.
  EXPECT_TRUE(std::isinf(forward_backward(m, {0, 15}).log_likelihood));
  EXPECT_TRUE(viterbi(m, {0, -1}).empty());
}

TEST(Hmm, BaumWelchLikelihoodNeverDecreases) {
  const HmmModel gen = seed002_trained_model();
  std::vector<std::vector<int>> seqs;
  for (int s = 0; s < 5; ++s) seqs.push_back(draw_hmm_sequence(gen, 400, 100 + s).symbols);
  BaumWelchOptions opt;
  opt.max_iterations = 60;
  opt.tolerance = -1e300;  // run every iteration, also past convergence
  const BaumWelchResult r = baum_welch(seed002_initial_model(1e-3), seqs, opt);
  ASSERT_EQ(r.iterations, 60);
  ASSERT_EQ(r.log_likelihood.size(), 61u);
  constexpr double kRoundingTol = 1e-9;  // relative: EM is monotone up to floating-point rounding
  for (std::size_t n = 1; n < r.log_likelihood.size(); ++n) {
    EXPECT_GE(r.log_likelihood[n], r.log_likelihood[n - 1] - kRoundingTol * std::abs(r.log_likelihood[n - 1]))
        << "iteration " << n;
  }
  EXPECT_GT(r.log_likelihood.back(), r.log_likelihood.front() + 100.0);  // it did learn something
  EXPECT_TRUE(r.model.problems().empty());
}

// Synthetic sequences drawn from seed 002's trained model (Table 2) -> Baum-Welch from seed 002's initial model
// (A1, Table 1) recovers the generator. 20 sequences of 2000 symbols: the sampling error of an entry p estimated
// from ~10^4 visits of a state is sqrt(p(1-p)/10^4) <= 0.005; the tolerance is 4 times that (a statistical bound,
// kept: any seed must pass). Measured 2026-12-05 (seeds 7-26): max |error| 0.0028 in A, 0.0109 in B.
TEST(Hmm, BaumWelchRecoversTheGenerator) {
  const HmmModel gen = seed002_trained_model();
  std::vector<std::vector<int>> seqs;
  for (int s = 0; s < 20; ++s) seqs.push_back(draw_hmm_sequence(gen, 2000, 7 + s).symbols);
  const BaumWelchResult r = baum_welch(seed002_initial_model(1e-3), seqs);
  EXPECT_TRUE(r.converged);
  constexpr double kTolProb = 0.02;
  const double errA = (r.model.A - gen.A).cwiseAbs().maxCoeff();
  const double errB = (r.model.B - gen.B).cwiseAbs().maxCoeff();
  EXPECT_LT(errA, kTolProb) << "trained A\n" << r.model.A;
  EXPECT_LT(errB, kTolProb) << "trained B\n" << r.model.B;
  // The generator's own likelihood is not above the trained one by more than sampling noise (EM found the ML
  // basin, not a worse local optimum).
  double ll_gen = 0.0;
  for (const auto& s : seqs) ll_gen += forward_backward(gen, s).log_likelihood;
  EXPECT_GE(r.log_likelihood.back(), ll_gen);
}

TEST(Hmm, DecodersFollowTheCycle) {
  const HmmModel gen = seed002_trained_model();
  const HmmDraw d = draw_hmm_sequence(gen, 3000, 42);
  const std::vector<int> v = viterbi(floored(gen, 1e-9), d.symbols);
  const std::vector<int> f = forward_decode(gen, d.symbols);
  ASSERT_EQ(v.size(), d.states.size());
  ASSERT_EQ(f.size(), d.states.size());
  int ok_v = 0, ok_f = 0;
  for (std::size_t t = 0; t < v.size(); ++t) {
    ok_v += v[t] == d.states[t];
    ok_f += f[t] == d.states[t];
  }
  // Table 2's emissions overlap only on grades 3 and 6 (A and C): both decoders get nearly every state. Measured
  // 2026-12-05 (seed 42): Viterbi 2999, forward 3000 of 3000; bound 99 % (30 misses: a few overlapping emissions more
  // on another draw).
  constexpr double kMinAccuracy = 0.99;
  EXPECT_GT(ok_v, kMinAccuracy * static_cast<double>(v.size()));
  EXPECT_GT(ok_f, kMinAccuracy * static_cast<double>(f.size()));
}

TEST(Hmm, QuantizationGrades) {
  constexpr double w = 1.0;
  EXPECT_EQ(quantize_rate(0.0, w), 8);   // grade 9 = [0, w)
  EXPECT_EQ(quantize_rate(0.99, w), 8);
  EXPECT_EQ(quantize_rate(1.01, w), 9);
  EXPECT_EQ(quantize_rate(-0.01, w), 7);  // grade 8 = [-w, 0)
  EXPECT_EQ(quantize_rate(-1.01, w), 6);
  EXPECT_EQ(quantize_rate(-100.0, w), 0);
  EXPECT_EQ(quantize_rate(100.0, w), 14);
}

// A synthetic gait signal about y: stance 0.4 s at 0, push-off -6 rad/s, swing +6 rad/s, heel strike -3 rad/s
// (half sines of 0.15, 0.35, 0.1 s), with a small ripple in stance. Returns samples at 200 Hz and the true
// stance intervals [t0, t1) in seconds.
std::vector<ImuSample> synthetic_gait(int cycles, std::vector<std::pair<double, double>>* stances) {
  constexpr double kRate_hz = 200.0, kPi = 3.14159265358979323846;
  struct Phase {
    double dur_s, amp_radps;
  };
  const Phase phases[] = {{0.4, 0.0}, {0.15, -6.0}, {0.35, 6.0}, {0.1, -3.0}};
  std::vector<ImuSample> s;
  double t = 0.0;
  for (int c = 0; c <= cycles; ++c) {
    for (int p = 0; p < 4; ++p) {
      if (c == cycles && p > 0) break;  // end in stance
      if (p == 0 && stances) stances->push_back({t, t + phases[p].dur_s});
      const int n = static_cast<int>(std::lround(phases[p].dur_s * kRate_hz));
      for (int k = 0; k < n; ++k) {
        ImuSample x;
        x.t = GpsTime::from_week_tow(0, t);
        const double u = (k + 0.5) / n;
        x.omega_ib_b.y() = phases[p].amp_radps * std::sin(kPi * u) + (p == 0 ? 0.02 * std::sin(60.0 * t) : 0.0);
        x.f_ib_b = Eigen::Vector3d(0, 0, -9.81);
        s.push_back(x);
        t += 1.0 / kRate_hz;
      }
    }
  }
  return s;
}

TEST(Hmm, ExtractionMergesRedundantExtremes) {
  std::vector<std::pair<double, double>> st;
  const auto s = synthetic_gait(3, &st);
  HmmObservationOptions o;
  o.grade_width_radps = 1.0;
  const GaitObservations g = extract_gait_observations(s, o);
  // Per cycle: stance (ripple merged into one grade-8 observation), push-off min, swing max, heel-strike min.
  const std::vector<int> expected = {8, 1, 13, 4, 8, 1, 13, 4, 8, 1, 13, 4, 8};
  std::vector<int> got = g.symbols();
  // Smoothing lowers the peaks by < 1 grade; accept +-1 grade on the extremes, exact order and count.
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t k = 0; k < got.size(); ++k) EXPECT_NEAR(got[k], expected[k], 1) << "observation " << k;
}

TEST(Hmm, StatesPerSampleMapsStanceToTheDwell) {
  std::vector<std::pair<double, double>> st;
  const auto s = synthetic_gait(3, &st);
  HmmObservationOptions o;
  o.grade_width_radps = 1.0;
  const GaitObservations g = extract_gait_observations(s, o);
  // The true state of each observation: the cycle D A B C ...
  std::vector<int> q;
  for (std::size_t k = 0; k < g.obs.size(); ++k) q.push_back(k % 4 == 0 ? kStance : static_cast<int>(k % 4) - 1);
  std::array<bool, kHmmSymbols> zero_grades{};
  zero_grades[7] = zero_grades[8] = true;
  const std::vector<int> per = states_per_sample(g, q, zero_grades);
  ASSERT_EQ(per.size(), s.size());
  // Stance samples: exactly the samples whose smoothed rate is within half a grade of zero around each true
  // stance; each true stance interval is covered to within the smoothing and the half-grade band (0.04 s).
  constexpr double kEdgeTol_s = 0.04;
  int runs = 0;
  for (std::size_t i = 0; i < per.size(); ++i) {
    if (per[i] != kStance || (i > 0 && per[i - 1] == kStance)) continue;
    std::size_t j = i;
    while (j + 1 < per.size() && per[j + 1] == kStance) ++j;
    ASSERT_LT(static_cast<std::size_t>(runs), st.size());
    const double t0 = s[i].t.tow_s(), t1 = s[j].t.tow_s();
    if (runs > 0) {
      EXPECT_NEAR(t0, st[runs].first, kEdgeTol_s) << "stance " << runs;
    }
    if (static_cast<std::size_t>(runs) + 1 < st.size()) {
      EXPECT_NEAR(t1, st[runs].second, kEdgeTol_s) << "stance " << runs;
    }
    ++runs;
  }
  EXPECT_EQ(runs, static_cast<int>(st.size()));
  // Swing samples lie in the swing phases only: the peak of the first swing is B.
  const std::size_t swing_peak = static_cast<std::size_t>((0.4 + 0.15 + 0.175) * 200.0);
  EXPECT_EQ(per[swing_peak], kSwing);
}

}  // namespace
}  // namespace pednav::ins
