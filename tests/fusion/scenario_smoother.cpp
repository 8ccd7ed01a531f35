// SPDX-License-Identifier: BSD-2-Clause
// RTS smoother of the closed-loop filter (issue 6) on the simulated forest walk (datasets/forest_walk.yaml, seed
// 004's outdoor test, simulated in memory as in scenario_tc.cpp): smoothed vs forward accuracy against the foot
// truth, smoothed sigma <= forward sigma at every output epoch, smoothed errors inside 3 sigma, and a 60 s full
// GNSS outage (forward vs smoothed error over the outage). Figures: docs/results.md "Smoother (issue 6)".
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/geodesy.hpp"
#include "fusion/engine.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "io/scenario_config.hpp"
#include "sim/simulator.hpp"

namespace pednav {
namespace {

constexpr double kMaxRmsRatio = 0.7;          // issue 6: smoothed horizontal RMS <= 0.7 x forward
constexpr double kMaxSmoothedRmsM = 1.2;      // issue 6
constexpr double kMaxSmoothedMaxM = 4.0;      // issue 6
constexpr double kMargin = 1.20;              // measured figure +20 % (docs/conventions.md "Test bounds")
// Issue 6: >= 99 % of epochs with the smoothed N and E errors inside 3 sigma. With white code errors in R (the
// default until 2026-12-01) it was 92.0 % (forward 83.2 %): the simulator's multipath is correlated for 20 s. With the
// code-multipath Gauss-Markov states (default since 2026-12-01, docs/consistency.md §3): 100.0 % forward and smoothed.
constexpr double kMinInside3SigmaPct = 99.0;
constexpr double kSigmaSlackM2 = 1e-9;        // [m²] round-off allowance for smoothed var <= forward var
constexpr double kSigmaSlackRad = 1e-9;       // [rad]
constexpr double kOutageStartAfterS = 460.0;  // [s] after the scenario start (walking; the static start is 120 s)
constexpr double kOutageS = 60.0;             // [s] full GNSS outage (issue 6)

struct Stats {
  double rms = 0, p95 = 0, max = 0, inside3_pct = 0;
  long n = 0;
};

struct Runs {
  sim::Simulation sim;
  fusion::EngineResult nominal, outage;
  double wall_s = 0;
};
Runs* g = nullptr;

const ins::NavState* truth_at(GpsTime t) {
  const auto& nav = g->sim.truth.nav;
  const long i = std::lround((t - nav.front().t) * g->sim.scenario.imu.rate_hz);
  if (i < 0 || i >= static_cast<long>(nav.size()) || std::abs(nav[i].t - t) > 1e-6) return nullptr;
  return &nav[i];
}

// Horizontal error statistics over output epochs with t in [t0, t1].
Stats stats(const std::vector<fusion::EpochOutput>& ep, GpsTime t0, GpsTime t1) {
  std::vector<double> e2;
  long inside = 0;
  for (const auto& e : ep) {
    if (e.t < t0 || t1 < e.t) continue;
    const ins::NavState* tr = truth_at(e.t);
    if (!tr) continue;
    const Eigen::Vector3d enu = enu_from_ecef(e.nav.p_eb_e, tr->p_eb_e);  // estimate − truth, ENU
    e2.push_back(enu.head<2>().norm());
    const double sn = std::sqrt(e.cov_p_n(0, 0)), se = std::sqrt(e.cov_p_n(1, 1));
    inside += std::abs(enu.y()) <= 3.0 * sn && std::abs(enu.x()) <= 3.0 * se;
  }
  Stats s;
  s.n = static_cast<long>(e2.size());
  if (e2.empty()) return s;
  double ss = 0;
  for (double v : e2) ss += v * v;
  s.rms = std::sqrt(ss / static_cast<double>(e2.size()));
  std::sort(e2.begin(), e2.end());
  s.p95 = e2[static_cast<size_t>(0.95 * static_cast<double>(e2.size() - 1))];
  s.max = e2.back();
  s.inside3_pct = 100.0 * static_cast<double>(inside) / static_cast<double>(e2.size());
  return s;
}

class ForestWalkSmoother : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto file = io::load_scenario("datasets/forest_walk.yaml");
    ASSERT_TRUE(file.has_value()) << file.error().message;
    auto s = sim::simulate(file->scenario);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    g = new Runs{std::move(*s), {}, {}, 0.0};
    io::RunConfig c;  // the configuration `pednav simulate` writes, mode tc: defaults of io::RunConfig
    c.mode = "tc";
    c.imu.spec = file->scenario.imu.spec;
    fusion::EngineOptions o = pipeline::engine_options(c);
    ASSERT_TRUE(o.smoother_enabled) << "smoother.enabled defaults to true";
    o.base_position_e = g->sim.gnss.p_base_e;
    fusion::EngineInputs in;
    in.imu = &g->sim.imu;
    in.nav = &g->sim.nav;
    in.rover = &g->sim.gnss.rover.epochs;
    in.base = &g->sim.gnss.base.epochs;
    const auto t0 = std::chrono::steady_clock::now();
    auto r = fusion::run_forward(in, o);
    g->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(r.has_value()) << r.error().message;
    g->nominal = std::move(*r);
    const GpsTime o0 = outage_start(), o1 = o0.plus_s(kOutageS);
    in.gnss_mask = [o0, o1](gnss::ObsEpoch& e) {
      if (!(e.time < o0) && e.time < o1) e.sats.clear();
    };
    auto r2 = fusion::run_forward(in, o);
    ASSERT_TRUE(r2.has_value()) << r2.error().message;
    g->outage = std::move(*r2);
    const auto& sm = g->nominal.summary;
    std::printf("[ smoother ] forward + smoother: %.1f s wall, %zu output epochs, %ld mechanization steps, %ld stored "
                "records, %ld bytes (%.0f bytes per output epoch, %.0f per mechanization step)\n",
                g->wall_s, g->nominal.epochs.size(), sm.mechanization_steps, sm.smoother_records, sm.smoother_bytes,
                static_cast<double>(sm.smoother_bytes) / static_cast<double>(std::max(1L, sm.smoother_records)),
                static_cast<double>(sm.smoother_bytes) / static_cast<double>(std::max(1L, sm.mechanization_steps)));
  }
  static void TearDownTestSuite() {
    delete g;
    g = nullptr;
  }
  static GpsTime outage_start() { return g->sim.scenario.start.plus_s(kOutageStartAfterS); }
  static GpsTime first() { return g->nominal.epochs.front().t; }
  static GpsTime last() { return g->nominal.epochs.back().t; }
};

TEST_F(ForestWalkSmoother, SmoothedEpochsMatchForwardEpochs) {
  const auto& r = g->nominal;
  ASSERT_TRUE(r.summary.smoothed);
  ASSERT_EQ(r.smoothed.size(), r.epochs.size());
  for (size_t k = 0; k < r.epochs.size(); ++k) {
    EXPECT_EQ(r.smoothed[k].t.ns(), r.epochs[k].t.ns());
    EXPECT_TRUE(r.smoothed[k].nav.p_eb_e.allFinite());
  }
  // The two solutions coincide at the last STEP of the filter, not at the last output epoch: the 1 Hz output ends
  // 0.280 s before the last IMU sample, and the backward pass starts from the tail (last output epoch -> last step,
  // forward_runner.cpp, eq. 12.10) that carries the stance updates of those 0.28 s (no GNSS epoch: the next is 1 s
  // later). Measured 2026-12-05: 1.78e-3 m between them at the last output epoch; bound +30 % (a millimetre-level
  // difference of two solutions; another libm/compiler). A smoother that ignored the tail would give 0 here, one that
  // started elsewhere decimetres: the bound's lower side is not checked (0 is a legitimate design).
  const double last_diff_m = (r.smoothed.back().nav.p_eb_e - r.epochs.back().nav.p_eb_e).norm();
  const double tail_s = g->sim.imu.back().t - r.epochs.back().t;
  std::printf("[ smoother ] last output epoch: smoothed - forward %.4e m, %.3f s before the last IMU sample\n",
              last_diff_m, tail_s);
  EXPECT_LT(last_diff_m, 1.30 * 1.78e-3);
  EXPECT_NEAR(tail_s, 0.280, 1e-6);  // from the data: the IMU log ends 0.28 s after a whole second
}

// The storage figures printed by SetUpTestSuite (docs/fusion.md §12.3: one composed record per output epoch, none per
// mechanization step). Measured 2026-12-06: 1081 records for 1081 output epochs and 21 606 mechanization steps,
// 16 623 632 bytes = 15 378 per record (769 per step). Bounds: the counts exact (the 1 Hz output and the 20 Hz
// mechanization grids over the log), the bytes per record +10 % (fixed by the state's size: a larger state is a change
// to measure again). The wall time is printed only: it is the machine's.
TEST_F(ForestWalkSmoother, StoresOneRecordPerOutputEpoch) {
  constexpr long kMechanizationSteps = 21606;
  constexpr double kBytesPerRecord = 15378.0;
  const auto& sm = g->nominal.summary;
  EXPECT_EQ(sm.smoother_records, static_cast<long>(g->nominal.epochs.size()));
  EXPECT_EQ(sm.mechanization_steps, kMechanizationSteps);
  ASSERT_GT(sm.smoother_records, 0);
  EXPECT_LT(static_cast<double>(sm.smoother_bytes) / static_cast<double>(sm.smoother_records), 1.10 * kBytesPerRecord);
}

TEST_F(ForestWalkSmoother, SmoothedSigmaNotAboveForwardSigma) {
  const auto& r = g->nominal;
  ASSERT_EQ(r.smoothed.size(), r.epochs.size());
  long strictly_smaller = 0;
  for (size_t k = 0; k < r.epochs.size(); ++k) {
    const auto& f = r.epochs[k];
    const auto& s = r.smoothed[k];
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(s.cov_p_n(i, i), f.cov_p_n(i, i) + kSigmaSlackM2) << f.t.to_string() << " position axis " << i;
      EXPECT_LE(s.cov_v_n(i, i), f.cov_v_n(i, i) + kSigmaSlackM2) << f.t.to_string() << " velocity axis " << i;
    }
    EXPECT_LE(s.sd_yaw_rad, f.sd_yaw_rad + kSigmaSlackRad) << f.t.to_string();
    strictly_smaller += s.cov_p_n(0, 0) < 0.9 * f.cov_p_n(0, 0);
  }
  // Not trivially equal: away from the end the smoother must reduce the variance.
  EXPECT_GT(strictly_smaller, static_cast<long>(r.epochs.size()) / 2);
}

TEST_F(ForestWalkSmoother, AccuracyAndConsistency) {
  const Stats f = stats(g->nominal.epochs, first(), last());
  const Stats s = stats(g->nominal.smoothed, first(), last());
  std::printf("[ smoother ] forest_walk horizontal, %ld epochs: forward RMS %.2f m, p95 %.2f m, max %.2f m, inside 3 "
              "sigma %.1f %%; smoothed RMS %.2f m, p95 %.2f m, max %.2f m, inside 3 sigma %.1f %%; ratio %.3f\n",
              f.n, f.rms, f.p95, f.max, f.inside3_pct, s.rms, s.p95, s.max, s.inside3_pct, s.rms / f.rms);
  EXPECT_LE(s.rms, kMaxRmsRatio * f.rms);
  EXPECT_LE(s.rms, kMaxSmoothedRmsM);
  EXPECT_LE(s.max, kMaxSmoothedMaxM);
  EXPECT_GE(s.inside3_pct, kMinInside3SigmaPct);
  // Measured 2026-12-05 (1081 epochs): forward RMS 1.08 m, p95 2.21 m, max 2.54 m, 100.0 % inside 3σ; smoothed
  // 0.45 / 0.95 / 0.97 m, 100.0 %; ratio 0.418. Bounds +20 % (kMargin; another libm/compiler), 99.5 % for the shares.
  EXPECT_EQ(f.n, 1081);
  EXPECT_LT(f.rms, kMargin * 1.08);
  EXPECT_LT(f.p95, kMargin * 2.21);
  EXPECT_LT(f.max, kMargin * 2.54);
  EXPECT_GE(f.inside3_pct, 99.5);
  EXPECT_LT(s.rms, kMargin * 0.45);
  EXPECT_LT(s.p95, kMargin * 0.95);
  EXPECT_LT(s.max, kMargin * 0.97);
  EXPECT_GE(s.inside3_pct, 99.5);
  EXPECT_LT(s.rms / f.rms, kMargin * 0.418);
}

TEST_F(ForestWalkSmoother, SixtySecondOutage) {
  ASSERT_GT(g->outage.summary.gnss_epochs_masked, static_cast<long>(kOutageS) - 2);
  const GpsTime o0 = outage_start(), o1 = o0.plus_s(kOutageS);
  const Stats f = stats(g->outage.epochs, o0, o1);
  const Stats s = stats(g->outage.smoothed, o0, o1);
  const Stats fa = stats(g->outage.epochs, first(), last());
  const Stats sa = stats(g->outage.smoothed, first(), last());
  std::printf("[ smoother ] 60 s outage from %s (%ld epochs): forward max %.2f m, RMS %.2f m; smoothed max %.2f m, RMS "
              "%.2f m, inside 3 sigma %.1f %%; whole run with the outage: forward RMS %.2f m, smoothed %.2f m\n",
              o0.to_string().c_str(), f.n, f.max, f.rms, s.max, s.rms, s.inside3_pct, fa.rms, sa.rms);
  EXPECT_GE(f.n, static_cast<long>(kOutageS) - 1);
  EXPECT_LT(s.max, f.max);
  EXPECT_LT(s.rms, f.rms);
  // Measured 2026-12-05 (61 epochs): forward max 1.38 m, RMS 1.21 m; smoothed max 0.31 m, RMS 0.28 m, 100.0 % inside
  // 3σ; whole run with the outage forward RMS 1.11 m, smoothed 0.44 m. Bounds +20 % (kMargin).
  EXPECT_EQ(f.n, 61);
  EXPECT_LT(f.max, kMargin * 1.38);
  EXPECT_LT(f.rms, kMargin * 1.21);
  EXPECT_LT(s.max, kMargin * 0.31);
  EXPECT_LT(s.rms, kMargin * 0.28);
  EXPECT_GE(s.inside3_pct, 99.5);
  EXPECT_LT(fa.rms, kMargin * 1.11);
  EXPECT_LT(sa.rms, kMargin * 0.44);
}

}  // namespace
}  // namespace pednav
