// SPDX-License-Identifier: BSD-2-Clause
// Calibration of datasets/forest_walk.yaml against seed 004 Table 1 (GPS-only LSQ, SiRF under canopy):
// `pednav gnss` on the simulated data, compared with truth.csv, gives a horizontal RMS of 5.3 m +- 25 % and
// 74.1 % +- 10 points of epochs under 5 m. Also checks the scenario's headline figures (18 min, ~900 m,
// ~660 strides, >= 7 satellites).
#include <gtest/gtest.h>

#include <chrono>

#include "eval/trajectory.hpp"
#include "io/config.hpp"
#include "pipeline/gnss_command.hpp"
#include "io/scenario_config.hpp"
#include "pipeline/simulate_command.hpp"
#include "io/trajectory_io.hpp"
#include "tests/sim/fixtures.hpp"
#include "tests/support/data.hpp"

namespace pednav {
namespace {

constexpr double kSeed004Rms_m = 5.3, kRmsTolFraction = 0.25;     // seed 004 Table 1, issue 4 tolerance
constexpr double kSeed004Lt5_pct = 74.1, kLt5Tol_pct = 10.0;
constexpr double kMaxGenerate_s = 15.0;  // issue target 5 s on an idle machine; loose here (shared CI cores)
// Measured 2026-12-05 (Release; the simulation and `pednav gnss` are deterministic): horizontal RMS 5.31 m, epochs
// under 5 m / 5-10 / 10-20 / >= 20 m 70.5 / 24.3 / 4.6 / 0.6 %, 1081 epochs compared. Bounds beside seed 004's
// targets: RMS +10 % / −10 %, the bins ±3 / ±3 / ±2 / ±1 percentage points (one epoch is 0.09 point); the epoch count
// exact (1 Hz over the 18-min scenario).
constexpr double kMeasuredRms_m = 5.31, kMeasuredRmsTolFraction = 0.10;
constexpr double kMeasuredBins_pct[4] = {70.5, 24.3, 4.6, 0.6};
constexpr double kMeasuredBinsTol_pct[4] = {3.0, 3.0, 2.0, 1.0};
constexpr int kEpochsCompared = 1081;

TEST(ForestWalk, PednavGnssLandsOnSeed004Table1) {
  auto sc = io::load_scenario(test::source_path("datasets/forest_walk.yaml"));
  ASSERT_TRUE(sc.has_value()) << (sc ? "" : sc.error().message);
  const std::string dir = test::temp_dir("forest_walk");
  const auto t0 = std::chrono::steady_clock::now();
  auto sum = pipeline::run_simulate_command(*sc, dir);
  const double gen_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(sum.has_value()) << (sum ? "" : sum.error().message);
  EXPECT_LT(gen_s, kMaxGenerate_s);
  // Measured 2026-12-05: 1080.3 s, 899.4 m, 659 strides (the plan is deterministic): ±1 s, ±2 m, ±2 strides around
  // the scenario's headline figures.
  EXPECT_NEAR(sum->duration_s, 18 * 60.0, 1.0);
  EXPECT_NEAR(sum->distance_m, 900.0, 2.0);
  EXPECT_NEAR(sum->strides, 660, 2);

  auto cfg = io::load_run_config(dir + "/config.yaml");
  ASSERT_TRUE(cfg.has_value()) << (cfg ? "" : cfg.error().message);
  // Seed 004's GPS-only solution is raw epoch-by-epoch code: calibrate against it without pednav's Doppler smoothing
  // (with the default 10 s smoothing: 4.62 m, 86.5 % < 5 m; docs/results.md).
  cfg->gnss.code_smoothing_s = 0.0;
  auto g = pipeline::run_gnss_command(*cfg, dir + "/G");
  ASSERT_TRUE(g.has_value()) << (g ? "" : g.error().message);
  auto sol = io::read_trajectory(dir + "/G/gnss.csv", {});
  auto ref = io::read_trajectory(dir + "/truth.csv", {});
  ASSERT_TRUE(sol && ref);
  auto ev = eval::compare(sol->trajectory, ref->trajectory, {});
  ASSERT_TRUE(ev.has_value()) << (ev ? "" : ev.error().message);
  std::printf("forest_walk: generated in %.2f s; pednav gnss: %d epochs, horizontal RMS %.2f m, <5 m %.1f %%, "
              "5-10 %.1f %%, 10-20 %.1f %%, >=20 %.1f %%\n",
              gen_s, ev->epochs_compared, ev->horizontal_rms_m, ev->bins_pct[0], ev->bins_pct[1], ev->bins_pct[2],
              ev->bins_pct[3]);
  EXPECT_EQ(ev->epochs_compared, kEpochsCompared);
  EXPECT_NEAR(ev->horizontal_rms_m, kSeed004Rms_m, kRmsTolFraction * kSeed004Rms_m);  // seed 004 Table 1
  EXPECT_NEAR(ev->bins_pct[0], kSeed004Lt5_pct, kLt5Tol_pct);                         // seed 004 Table 1
  EXPECT_NEAR(ev->horizontal_rms_m, kMeasuredRms_m, kMeasuredRmsTolFraction * kMeasuredRms_m);
  for (int b = 0; b < 4; ++b) EXPECT_NEAR(ev->bins_pct[b], kMeasuredBins_pct[b], kMeasuredBinsTol_pct[b]) << "bin " << b;
  std::printf("forest_walk: %.1f s, %.1f m, %d strides\n", sum->duration_s, sum->distance_m, sum->strides);
}

}  // namespace
}  // namespace pednav
