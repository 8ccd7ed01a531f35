// SPDX-License-Identifier: BSD-2-Clause
// A hand-held IMU with GNSS (issue 49 item 4; datasets/forest_walk_hand.yaml: forest_walk's route, receiver, canopy and
// seed with the device in the hand, docs/sim.md §9): the engine recognizes an IMU that is not on a foot (ZUPTs only
// while the walker stands, heading from the GNSS course, the Doppler rows on the IMU's own velocity, the non-holonomic
// constraint of a hand; docs/fusion.md §8.2) and the tight coupling does better than `pednav gnss` on the same files.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <algorithm>
#include <map>
#include <sstream>
#include <string>
#include <vector>

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

// Measured 2026-12-06 (Release, deterministic): `pednav gnss` 4.62 m horizontal RMS; `pednav run` forward 1.67 m
// (0.36x), smoothed 0.98 m (0.21x). Of the 18 one-minute windows the forward solution is above the GNSS-only one in 2
// (the first, standing at the start; one straight leg at 360-420 s), the smoothed one in none. Without the ZUPTs
// while the walker stands (eq. 8.5): forward 1.76 m (0.38x), smoothed 1.15 m (0.25x); without the hand-held
// non-holonomic constraint (eq. 8.4) as well: 2.27 m (0.49x), 1.74 m (0.38x); before the not-on-foot recognition the
// run did not initialize (heading from an INS/ZUPT track that never had a ZUPT). Issue 49's target: <= 0.8x over the
// whole walk (met) and never above over any 60-s window (smoothed: met; forward: 2 of 18). Bounds: the measured
// ratios + 5 % forward, + 10 % smoothed (below the figures without eq. 8.5), the window counts exactly; the ZUPT
// epochs: 252 of the 254 output epochs at which the simulated walker stands, none while it moves.
constexpr double kForwardRatio = 0.36, kSmoothedRatio = 0.21;
constexpr int kForwardWindowsAbove = 2, kSmoothedWindowsAbove = 0;
constexpr int kStandingZuptEpochs = 252;

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
  EXPECT_LT(rf, kForwardRatio * 1.05);
  EXPECT_LT(rs, kSmoothedRatio * 1.10);
  EXPECT_EQ(windows, 18);
  EXPECT_EQ(above_f, kForwardWindowsAbove);
  EXPECT_EQ(above_s, kSmoothedWindowsAbove);
  // ZUPTs while the walker stands (eq. 8.5), never while it moves: solution.csv's zupt flag against the truth's speed.
  std::map<long long, double> speed;
  {
    std::ifstream in(truth);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      std::stringstream ss(line);
      std::string c[11];
      for (auto& x : c) std::getline(ss, x, ',');
      speed[std::llround(std::stod(c[1]) * 1e3)] = std::hypot(std::stod(c[8]), std::stod(c[9]));
    }
  }
  int zupt_standing = 0, zupt_moving = 0;
  {
    std::ifstream in(dir + "/run/solution.csv");
    std::string line;
    std::getline(in, line);
    std::vector<std::string> header;
    std::stringstream hs(line);
    for (std::string x; std::getline(hs, x, ',');) header.push_back(x);
    const size_t it = std::find(header.begin(), header.end(), "gps_tow_s") - header.begin();
    const size_t iz = std::find(header.begin(), header.end(), "zupt") - header.begin();
    ASSERT_LT(iz, header.size());
    while (std::getline(in, line)) {
      std::stringstream ss(line);
      std::vector<std::string> c;
      for (std::string x; std::getline(ss, x, ',');) c.push_back(x);
      if (c.size() <= iz || c[iz] != "1") continue;
      const auto sp = speed.find(std::llround(std::stod(c[it]) * 1e3));
      if (sp == speed.end()) continue;
      (sp->second < 0.05 ? zupt_standing : zupt_moving) += 1;
    }
  }
  std::printf("[hand-held forest walk] ZUPT at %d output epochs while standing, %d while moving\n", zupt_standing,
              zupt_moving);
  EXPECT_EQ(zupt_moving, 0);
  EXPECT_NEAR(zupt_standing, kStandingZuptEpochs, 5);
}

}  // namespace
}  // namespace pednav
