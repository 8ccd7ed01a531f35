// SPDX-License-Identifier: BSD-2-Clause
// A hand-held IMU with GNSS (issue 49 item 4; datasets/forest_walk_hand.yaml: forest_walk's route, receiver, canopy and
// seed with the device in the hand, docs/sim.md §9): the engine recognizes an IMU that is not on a foot (no ZUPT after
// the levelling window, heading from the GNSS course, the Doppler rows on the IMU's own velocity, the non-holonomic
// constraint of a hand; docs/fusion.md §8.2) and the tight coupling does better than `pednav gnss` on the same files.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>

#include "io/config.hpp"
#include "io/scenario_config.hpp"
#include "pipeline/compare_command.hpp"
#include "pipeline/gnss_command.hpp"
#include "pipeline/run_command.hpp"
#include "pipeline/simulate_command.hpp"
#include "tests/sim/fixtures.hpp"
#include "tests/support/data.hpp"

namespace pednav {
namespace {

eval::Evaluation compare(const std::string& solution, const std::string& truth, const std::string& out) {
  pipeline::CompareArgs args;
  args.solution = solution;
  args.reference = truth;
  args.out_dir = out;
  args.plots = false;
  auto ev = pipeline::run_compare(args);
  EXPECT_TRUE(ev) << ev.error().message;
  return ev ? *ev : eval::Evaluation{};
}

// Horizontal RMS per 60-s window from the first epoch (windows with at least 30 epochs), keyed by the window start [s].
std::map<int, double> window_rms(const eval::Evaluation& ev) {
  std::map<int, std::pair<double, int>> acc;
  if (ev.errors.empty()) return {};
  const GpsTime t0 = ev.errors.front().t;
  for (const auto& e : ev.errors) {
    auto& a = acc[60 * static_cast<int>(std::floor((e.t - t0) / 60.0))];
    a.first += e.horizontal_m * e.horizontal_m;
    ++a.second;
  }
  std::map<int, double> out;
  for (const auto& [w, a] : acc) {
    if (a.second >= 30) out[w] = std::sqrt(a.first / a.second);
  }
  return out;
}

// Measured 2026-12-06 (Release, deterministic): `pednav gnss` 4.62 m horizontal RMS; `pednav run` forward 1.76 m
// (0.38x), smoothed 1.15 m (0.25x). Of the 18 one-minute windows the forward solution is above the GNSS-only one in 2
// (the first, standing at the start: 0.39 against 0.35 m; 360-420 s: 1.51 against 1.15 m), the smoothed one in none.
// Without the hand-held non-holonomic constraint (eq. 8.4): forward 2.27 m (0.49x), smoothed 1.74 m (0.38x); before
// the not-on-foot recognition the run did not initialize (heading from an INS/ZUPT track that never had a ZUPT).
// Issue 49's target: <= 0.8x over the whole walk (met) and never above over any 60-s window (smoothed: met; forward:
// 2 of 18). Bounds: the measured ratios + 15 % (below the figures without the constraint), the window counts exactly.
constexpr double kForwardRatio = 0.38, kSmoothedRatio = 0.25;
constexpr int kForwardWindowsAbove = 2, kSmoothedWindowsAbove = 0;

TEST(HandHeld, TheTightCouplingOfAHandHeldImuBeatsTheGnssEpochSolution) {
  auto file = io::load_scenario(test::source_path("datasets/forest_walk_hand.yaml"));
  ASSERT_TRUE(file) << file.error().message;
  const std::string dir = test::temp_dir("hand_held");
  ASSERT_TRUE(pipeline::run_simulate_command(*file, dir + "/data").has_value());
  auto cfg = io::load_run_config(dir + "/data/config.yaml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->antenna.velocity_model, "foot");  // the written configuration: the device's own antenna
  EXPECT_EQ(cfg->antenna.lever_arm_ned_m, Eigen::Vector3d::Zero());
  ASSERT_TRUE(pipeline::run_gnss_command(*cfg, dir + "/gnss").has_value());
  auto sum = pipeline::run_run_command(*cfg, dir + "/run");
  ASSERT_TRUE(sum) << sum.error().message;
  std::ifstream js(dir + "/run/summary.json");
  const auto summary = nlohmann::json::parse(js);
  const std::string init = summary["initialization"].get<std::string>();
  EXPECT_NE(init.find("an IMU not on a foot"), std::string::npos) << init;
  EXPECT_NE(init.find("heading from the GNSS course"), std::string::npos) << init;
  const std::string truth = dir + "/data/truth.csv";
  const auto g = compare(dir + "/gnss/gnss.csv", truth, dir + "/cmp_gnss");
  const auto f = compare(dir + "/run/solution.csv", truth, dir + "/cmp_fwd");
  const auto s = compare(dir + "/run/smoothed.csv", truth, dir + "/cmp_smo");
  ASSERT_GT(g.horizontal_rms_m, 0.0);
  const double rf = f.horizontal_rms_m / g.horizontal_rms_m, rs = s.horizontal_rms_m / g.horizontal_rms_m;
  const auto wg = window_rms(g), wf = window_rms(f), ws = window_rms(s);
  int above_f = 0, above_s = 0, windows = 0;
  for (const auto& [w, r] : wf) {
    if (!wg.count(w) || !ws.count(w)) continue;
    ++windows;
    above_f += r > wg.at(w);
    above_s += ws.at(w) > wg.at(w);
  }
  std::printf("[hand-held forest walk] gnss %.2f m, tc forward %.2f m (%.2fx), smoothed %.2f m (%.2fx); above gnss in "
              "%d (forward) and %d (smoothed) of %d 60-s windows\n",
              g.horizontal_rms_m, f.horizontal_rms_m, rf, s.horizontal_rms_m, rs, above_f, above_s, windows);
  EXPECT_LT(rf, 0.8);  // issue 49
  EXPECT_LT(rf, kForwardRatio * 1.15);
  EXPECT_LT(rs, kSmoothedRatio * 1.15);
  EXPECT_EQ(windows, 18);
  EXPECT_EQ(above_f, kForwardWindowsAbove);
  EXPECT_EQ(above_s, kSmoothedWindowsAbove);
}

}  // namespace
}  // namespace pednav
