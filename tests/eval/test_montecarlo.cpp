// SPDX-License-Identifier: BSD-2-Clause
// Monte Carlo aggregation (eval/montecarlo.*, issue 9): χ² band quantiles against table values, NEES and σ ratio
// on synthetic runs with a known covariance (consistent → inside the band; errors 1.5× too large → above it), and
// seed 000's reduced per-channel Kalman filter (δV, β, ε with the Schuler term): with M runs the sample σ of the
// estimation error matches √P₁₁ (seed 000 Figs. 4-5).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>
#include <random>

#include "eval/montecarlo.hpp"

namespace pednav::eval {
namespace {

// χ² quantiles from standard tables (Abramowitz & Stegun 1964 Table 26.8 / NIST handbook) [-].
constexpr double kChi2_975_100 = 129.561, kChi2_025_100 = 74.222;
constexpr double kChi2_975_200 = 241.058, kChi2_025_200 = 162.728;
constexpr double kQuantileRelTol = 2e-3;  // Wilson-Hilferty at dof >= 100 [-]

TEST(MonteCarloStats, NormalQuantileMatchesKnownValues) {
  EXPECT_NEAR(normal_quantile(0.975), 1.959963985, 1e-9);
  EXPECT_NEAR(normal_quantile(0.5), 0.0, 1e-12);
  EXPECT_NEAR(normal_quantile(0.001), -3.090232306, 1e-8);
  EXPECT_TRUE(std::isnan(normal_quantile(1.0)));
}

TEST(MonteCarloStats, ChiSquareQuantilesMatchTables) {
  EXPECT_NEAR(chi_square_quantile_wh(0.975, 100) / kChi2_975_100, 1.0, kQuantileRelTol);
  EXPECT_NEAR(chi_square_quantile_wh(0.025, 100) / kChi2_025_100, 1.0, kQuantileRelTol);
  EXPECT_NEAR(chi_square_quantile_wh(0.975, 200) / kChi2_975_200, 1.0, kQuantileRelTol);
  EXPECT_NEAR(chi_square_quantile_wh(0.025, 200) / kChi2_025_200, 1.0, kQuantileRelTol);
  // Average NEES of 100 runs of a 2-dof error: [162.7, 241.1] / 100.
  const auto [lo, hi] = average_nees_band(100, 2);
  EXPECT_NEAR(lo, kChi2_025_200 / 100, kQuantileRelTol * lo);
  EXPECT_NEAR(hi, kChi2_975_200 / 100, kQuantileRelTol * hi);
}

// M runs of K epochs whose horizontal errors are drawn from N(0, scale² P_k) with the filter reporting P_k.
std::vector<McRun> synthetic_runs(int runs, int epochs, double scale, uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  std::vector<McRun> out(runs);
  for (auto& r : out) {
    for (int k = 0; k < epochs; ++k) {
      McEpoch e;
      e.t_s = k;
      e.distance_m = 1.1 * k;
      const double sn = 0.5 + 0.01 * k, se = 0.3 + 0.02 * k, rho = 0.6;  // [m], [-]
      e.cov_ned_m2 << sn * sn, rho * sn * se, 0, rho * sn * se, se * se, 0, 0, 0, 1.0;
      const Eigen::Matrix3d L = e.cov_ned_m2.llt().matrixL();
      e.err_ned_m = scale * L * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      e.var_yaw_rad2 = 1e-4 * (1 + k);
      e.err_yaw_rad = scale * std::sqrt(e.var_yaw_rad2) * n01(rng);
      r.forward.push_back(e);
    }
  }
  return out;
}

constexpr int kRuns = 200, kEpochs = 300;
// Measured 2026-12-05 (seed 7, libstdc++'s normal_distribution): NEES in band 0.953, mean NEES 1.996, σ ratio
// horizontal 1.003, yaw 0.994, inside 3σ 0.9949. These bounds stay the statistical ones, wider than the measured
// figures: the test is of the statistics (any seed of a consistent filter must pass), and the epochs' figures are
// correlated across the 300 epochs of a run, so their spread is larger than M·K = 60 000 independent draws suggest.
constexpr double kMinInBand = 0.9;        // a consistent filter: ~95 % of epochs in the 95 % band [-]
constexpr double kRatioTol = 0.05;        // σ ratio of a consistent filter within 5 % of 1 (M·K = 60 000 draws) [-]

TEST(MonteCarloStats, ConsistentRunsAreInsideTheBand) {
  const auto runs = synthetic_runs(kRuns, kEpochs, 1.0, 7);
  const auto st = aggregate_epochs(runs, false, 2);
  ASSERT_EQ(st.size(), static_cast<size_t>(kEpochs));
  EXPECT_EQ(st[10].runs, kRuns);
  const McSummary s = summarize(st, kRuns);
  std::printf("[ consistent ] NEES in band %.3f, mean NEES %.3f, sigma ratio h %.3f yaw %.3f, 3-sigma %.4f\n",
              s.nees_in_band_fraction, s.mean_nees_horizontal, s.sigma_ratio_horizontal, s.sigma_ratio_yaw,
              s.inside_3sigma_fraction);
  EXPECT_GE(s.nees_in_band_fraction, kMinInBand);
  EXPECT_GE(s.nees_yaw_in_band_fraction, kMinInBand);
  EXPECT_NEAR(s.mean_nees_horizontal, 2.0, 2.0 * kRatioTol);
  EXPECT_NEAR(s.sigma_ratio_horizontal, 1.0, kRatioTol);
  EXPECT_NEAR(s.sigma_ratio_yaw, 1.0, kRatioTol);
  EXPECT_NEAR(s.sigma_ratio_horizontal_pooled, 1.0, kRatioTol);
  EXPECT_NEAR(s.sigma_ratio_yaw_pooled, 1.0, kRatioTol);
  EXPECT_GT(s.inside_3sigma_fraction, 0.98);
  // Distance is the mean over runs; the sample σ of each axis follows P.
  EXPECT_NEAR(st[100].distance_m, 110.0, 1e-9);
  EXPECT_NEAR(st[100].filter_sd_ned_m.y(), 2.3, 1e-12);
}

TEST(MonteCarloStats, OptimisticFilterIsAboveTheBand) {
  const auto runs = synthetic_runs(kRuns, kEpochs, 1.5, 8);
  const McSummary s = summarize(aggregate_epochs(runs, false, 2), kRuns);
  EXPECT_LT(s.nees_in_band_fraction, 0.1);
  EXPECT_GT(s.nees_above_band_fraction, 0.9);
  EXPECT_NEAR(s.mean_nees_horizontal, 2.0 * 1.5 * 1.5, 2.0 * 1.5 * 1.5 * kRatioTol);
  EXPECT_NEAR(s.sigma_ratio_horizontal, 1.5, 1.5 * kRatioTol);
  EXPECT_NEAR(s.sigma_ratio_yaw, 1.5, 1.5 * kRatioTol);
  EXPECT_NEAR(s.sigma_ratio_horizontal_pooled, 1.5, 1.5 * kRatioTol);
}

TEST(MonteCarloStats, WindowBandsCountTheEpochsOfEachWindow) {
  std::vector<McEpochStats> ep(400);
  for (int i = 0; i < 400; ++i) {
    McEpochStats& e = ep[static_cast<size_t>(i)];
    e.t_s = i;
    e.nees_lo_2dof = 1.6;
    e.nees_hi_2dof = 2.4;
    e.nees_horizontal = i >= 150 && i < 225 ? 3.0 : 2.0;  // half of the second window above the band
  }
  const auto w = window_bands(ep, 150.0);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_DOUBLE_EQ(w[0].from_s, 0.0);
  EXPECT_DOUBLE_EQ(w[1].to_s, 300.0);
  EXPECT_EQ(w[0].epochs, 150);
  EXPECT_EQ(w[2].epochs, 100);  // the last window is partial
  EXPECT_DOUBLE_EQ(w[0].nees_in_band_fraction, 1.0);
  EXPECT_DOUBLE_EQ(w[1].nees_in_band_fraction, 0.5);
  EXPECT_DOUBLE_EQ(w[1].mean_nees_horizontal, 2.5);
  EXPECT_DOUBLE_EQ(w[2].nees_in_band_fraction, 1.0);
  EXPECT_TRUE(window_bands(ep, 0.0).empty());
}

TEST(MonteCarloStats, EpochsMissingInManyRunsAreLeftOut) {
  auto runs = synthetic_runs(10, 5, 1.0, 9);
  runs[0].forward.pop_back();  // the last epoch is in 9 runs only
  EXPECT_EQ(aggregate_epochs(runs, false, 10).size(), 4u);
  EXPECT_EQ(aggregate_epochs(runs, false, 9).size(), 5u);
  EXPECT_TRUE(aggregate_epochs(runs, true, 2).empty());  // no smoothed epochs given
}

// Seed 000's reduced eastern channel x = [δV_E, β_N, ε_N]: Φ = [[1, −gT, 0], [T/R, 1, T], [0, 0, 1]],
// Q = diag(σa², 0, σε²), measurement S = δV_E + n (H = [1 0 0]), Kalman filter eq. (4).
// Paper values: T = 0.5 s, σa = 0.1 m/s, σε = 1e-6 1/s, σn = 0.5 m/s. M ≥ 1000 runs (issue 9).
constexpr double kG = 9.81;           // [m/s²]
constexpr double kEarthR = 6371000.0; // R_3 [m]
constexpr double kT = 0.5;            // step period [s]
constexpr double kSigmaA = 0.1;       // [m/s] per step
constexpr double kSigmaEps = 1e-6;    // [rad/s] per step
constexpr double kSigmaN = 0.5;       // [m/s]
constexpr int kMcRuns = 2000;         // M
constexpr int kSteps = 1200;          // K (10 minutes)
constexpr double kSigmaMatchTol = 0.10;  // issue 9: sample σ within 10 % of √P11 (SE of σ at M = 2000: 1.6 %)

// summarize_carrier pools the runs' carrier figures: rates over all epochs, NEES over all fixed epochs, the first-fix
// times of the runs with a fix only (a run never fixed has none).
TEST(MonteCarloStats, CarrierSummaryPoolsTheRuns) {
  std::vector<McRun> runs(3);
  runs[0].carrier = {100, 40, 0, 80.0, 30.0};
  runs[1].carrier = {100, 10, 10, 1000.0, 90.0};
  runs[2].carrier = {50, 0, 0, 0.0, -1.0};
  const McCarrierSummary s = summarize_carrier(runs);
  EXPECT_EQ(s.runs, 3);
  EXPECT_EQ(s.gnss_epochs, 250);
  EXPECT_EQ(s.fixed_epochs, 50);
  EXPECT_EQ(s.wrong_fixed_epochs, 10);
  EXPECT_DOUBLE_EQ(s.fix_rate, 0.2);
  EXPECT_DOUBLE_EQ(s.wrong_fix_rate, 0.2);
  EXPECT_EQ(s.runs_with_fix, 2);
  EXPECT_EQ(s.runs_with_wrong_fix, 1);
  EXPECT_DOUBLE_EQ(s.mean_antenna_nees_fixed, 1080.0 / 50.0);
  EXPECT_DOUBLE_EQ(s.median_time_to_first_fix_s, 60.0);
  EXPECT_DOUBLE_EQ(s.max_time_to_first_fix_s, 90.0);
  const McCarrierSummary none = summarize_carrier(std::vector<McRun>(2));
  EXPECT_EQ(none.fixed_epochs, 0);
  EXPECT_EQ(none.wrong_fix_rate, 0.0);
  EXPECT_LT(none.median_time_to_first_fix_s, 0.0) << "no fix: no first-fix time";
}

TEST(Seed000ChannelFilter, SampleSigmaMatchesFilterSigma) {
  Eigen::Matrix3d Phi;
  Phi << 1, -kG * kT, 0, kT / kEarthR, 1, kT, 0, 0, 1;
  const Eigen::Matrix3d Q = Eigen::Vector3d(kSigmaA * kSigmaA, 0, kSigmaEps * kSigmaEps).asDiagonal();
  const Eigen::RowVector3d H(1, 0, 0);
  const Eigen::Matrix3d P0 = Eigen::Vector3d(0.3 * 0.3, 2e-3 * 2e-3, 1e-4 * 1e-4).asDiagonal();
  // The covariance sequence is the same for every run (Φ, Q, H, R constant): compute it once.
  std::vector<double> p11(kSteps);
  std::vector<Eigen::Vector3d> gain(kSteps);
  Eigen::Matrix3d P = P0;
  for (int k = 0; k < kSteps; ++k) {
    P = Phi * P * Phi.transpose() + Q;
    const double s = H * P * H.transpose() + kSigmaN * kSigmaN;
    gain[k] = P * H.transpose() / s;
    P = (Eigen::Matrix3d::Identity() - gain[k] * H) * P;
    p11[k] = P(0, 0);
  }
  std::vector<double> sum(kSteps, 0.0), sum2(kSteps, 0.0);
  std::mt19937_64 rng(2017);
  std::normal_distribution<double> n01;
  const Eigen::Matrix3d L0 = P0.llt().matrixL();
  for (int j = 0; j < kMcRuns; ++j) {
    Eigen::Vector3d x = L0 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));  // truth
    Eigen::Vector3d xh = Eigen::Vector3d::Zero();                            // estimate
    for (int k = 0; k < kSteps; ++k) {
      x = Phi * x + Eigen::Vector3d(kSigmaA * n01(rng), 0.0, kSigmaEps * n01(rng));
      const double meas = x(0) + kSigmaN * n01(rng);
      xh = Phi * xh;
      xh += gain[k] * (meas - xh(0));
      const double e = x(0) - xh(0);  // e_E(k) = δV_E − δV̂_E
      sum[k] += e;
      sum2[k] += e * e;
    }
  }
  double worst = 1.0;
  int worst_k = 0;
  for (int k = 0; k < kSteps; ++k) {
    const double mean = sum[k] / kMcRuns;
    const double sd = std::sqrt((sum2[k] - kMcRuns * mean * mean) / (kMcRuns - 1));
    const double r = sd / std::sqrt(p11[k]);
    if (std::abs(r - 1.0) > std::abs(worst - 1.0)) worst = r, worst_k = k;
    ASSERT_NEAR(r, 1.0, kSigmaMatchTol) << "step " << k;
  }
  std::printf("[ seed 000 ] M = %d, K = %d: sqrt(P11) %.4f m/s at the end; worst sample/filter sigma ratio %.4f at "
              "step %d\n",
              kMcRuns, kSteps, std::sqrt(p11.back()), worst, worst_k);
  // Measured 2026-12-05 (seed 2017, libstdc++): √P11 0.2161 m/s at the end (deterministic: the covariance recursion),
  // worst |sample σ / filter σ − 1| 0.0486 over the 1200 steps (the largest of 1200 correlated estimates whose SE is
  // 1.6 %: about 3 SE). Beside the 10 %: √P11 ±0.5 %, the worst deviation + 30 % (fixed seed).
  EXPECT_NEAR(std::sqrt(p11.back()), 0.2161, 0.005 * 0.2161);
  EXPECT_LT(std::abs(worst - 1.0), 1.3 * 0.0486);
  // The check can fail: a filter that under-reports its σ by 20 % is caught.
  const double mean = sum.back() / kMcRuns;
  const double sd = std::sqrt((sum2.back() - kMcRuns * mean * mean) / (kMcRuns - 1));
  EXPECT_GT(std::abs(sd / (0.8 * std::sqrt(p11.back())) - 1.0), kSigmaMatchTol);
}

}  // namespace
}  // namespace pednav::eval
