// SPDX-License-Identifier: BSD-2-Clause
// The out-of-the-box configuration (datasets/foot/pyshoe_auto.yaml: the minimal one, whose `imu.spec` and
// `zupt.shoe_threshold` default to `auto`; every other key default) on all 24 PyShoe Vicon trials, scored as
// scripts/pyshoe_cv does, and on the x-io loops.
// The auto knobs were chosen on the 24 trials by leave-one-session-out cross-validation (the ZARU gate and stance
// edges of `auto` on the 4 `original` trials); the x-io loops are held out (docs/results.md "Out of the box").
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>

#include "io/config.hpp"
#include "pipeline/compare_command.hpp"
#include "pipeline/run_command.hpp"
#include "tests/support/data.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::pipeline {
namespace {

using namespace pednav::io;

// The auto knobs (motion allowance 2.5, adaptive factor 4, swing 360 °/s, two-class split capped at 10) were chosen by
// leave-one-session-out cross-validation on all 24 trials (scripts/pyshoe_loso): every figure here is in-sample for
// that choice; the cross-validated (out-of-fold) figures are in docs/results.md "Out of the box" (all 24: median
// 1.198x PyShoe's per-trial tuned error, worst 3.36x). Measured 2026-12-06 (Release; scripts/pyshoe_cv
// datasets/foot/pyshoe_auto.yaml): `original` trials median 0.90x, worst 1.09x, 4/4 better than PyShoe with one
// threshold; `added` trials median 1.294x (1.365x before the turning-window test of docs/ins.md eq. 10.2), worst
// 2.59x (2018-02-09-11-22-01), 17/20. Bounds: measured + 5 %
// (deterministic runs; the margin is for another libm), counts exact. Issue 37's targets (median <= 1.0x, worst <=
// 2.0x, >= 90 % better than one threshold) are NOT met and not asserted.
constexpr double kOriginalMedianMax = 0.90 * 1.05;
constexpr double kOriginalWorstMax = 1.09 * 1.05;
constexpr double kAddedMedianMax = 1.294 * 1.05;
constexpr double kAddedWorstMax = 2.59 * 1.05;
constexpr int kAddedBeatsOneThresholdMin = 17;
// x-io loops with the same configuration (held out: never used to choose an auto knob), measured 0.058 m / 0.156 m
// end-point error (the committed x-io configuration, chosen on these loops: 0.023 / 0.122 m) over a path of 25.2 m /
// 60.0 m (measured 2026-12-06). The path length is checked too (a run that lost strides would close well): ±0.5 m, as
// data_foot_ins.cpp (a lost or extra stride moves it by about 1 m).
constexpr double kXioShortClosureMax_m = 0.058 * 1.05;
constexpr double kXioLongClosureMax_m = 0.156 * 1.05;
constexpr double kXioShortDistance_m = 25.2, kXioLongDistance_m = 60.0, kXioDistanceTol_m = 0.5;

struct Trial {
  std::string name, split;
  double tuned_m = 0.0, one_threshold_m = 0.0, pednav_m = 0.0;
};

std::vector<Trial> read_trials() {
  std::vector<Trial> out;
  std::ifstream in(test::shared_data("foot_pyshoe_vicon/trials.csv"));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> head;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) head.push_back(c);
  }
  auto col = [&](const char* name) { return std::find(head.begin(), head.end(), name) - head.begin(); };
  const auto i_trial = col("trial"), i_split = col("split"), i_tuned = col("pyshoe_tuned_mean_horizontal_m"),
             i_one = col("pyshoe_one_threshold_mean_horizontal_m");
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (cells.size() < head.size()) continue;
    out.push_back({cells[i_trial], cells[i_split], std::stod(cells[i_tuned]), std::stod(cells[i_one]), 0.0});
  }
  return out;
}

std::filesystem::path fresh_dir_path(const std::string& name) {
  return test::temp_dir_path("data_foot_auto_" + name);
}

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = fresh_dir_path(name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// scripts/pyshoe_cv's figure: start-aligned mean horizontal error against the Vicon (e = gt_y, n = gt_x).
// `tweak` changes the configuration (a study of one key); `summary` receives the run's counts.
double run_trial(const std::string& trial, const std::function<void(RunConfig&)>& tweak = {},
                 fusion::EngineSummary* summary = nullptr) {
  const std::string log = test::shared_data("foot_pyshoe_vicon/csv/" + trial + ".csv");
  const auto out = fresh_dir(trial);
  {
    std::ifstream in(log);
    std::ofstream ref(out / "ref.csv");
    std::string line;
    std::getline(in, line);
    ref << "gps_week,gps_tow_s,e_m,n_m,u_m\n";
    while (std::getline(in, line)) {
      std::stringstream ss(line);
      std::string cell[10];
      for (auto& c : cell) std::getline(ss, c, ',');
      ref << "0," << cell[0] << ',' << cell[8] << ',' << cell[7] << ',' << cell[9] << '\n';
    }
  }
  auto cfg = load_run_config(test::source_path("datasets/foot/pyshoe_auto.yaml"));
  EXPECT_TRUE(cfg) << cfg.error().message;
  if (!cfg) return 1e9;
  cfg->imu.file = log;
  if (tweak) tweak(*cfg);
  auto sum = run_run_command(*cfg, (out / "run").string());
  EXPECT_TRUE(sum) << trial << ": " << sum.error().message;
  if (!sum) return 1e9;
  if (summary) *summary = *sum;
  CompareArgs args;
  args.solution = (out / "run" / "solution.csv").string();
  args.reference = (out / "ref.csv").string();
  args.out_dir = (out / "cmp").string();
  args.compare.align = eval::Align::kStart;
  args.plots = false;
  auto ev = run_compare(args);
  EXPECT_TRUE(ev) << trial << ": " << ev.error().message;
  return ev ? ev->horizontal_mean_m : 1e9;
}

struct GroupFigures {
  double median = 0.0, worst = 0.0;
  int beats = 0, trials = 0;
};
GroupFigures figures(const std::vector<Trial>& t, bool tuning) {
  GroupFigures g;
  std::vector<double> r;
  for (const auto& x : t) {
    if ((x.split == "original") != tuning) continue;
    r.push_back(x.pednav_m / x.tuned_m);
    g.beats += x.pednav_m < x.one_threshold_m;
  }
  g.trials = static_cast<int>(r.size());
  if (r.empty()) return g;
  std::sort(r.begin(), r.end());
  g.median = r.size() % 2 ? r[r.size() / 2] : 0.5 * (r[r.size() / 2 - 1] + r[r.size() / 2]);
  g.worst = r.back();
  return g;
}

TEST(DataFootAuto, PyshoeTrialsOriginalAndAdded) {
  PEDNAV_REQUIRE_DATA(test::shared_data("foot_pyshoe_vicon/trials.csv"));
  std::vector<Trial> trials = read_trials();
  ASSERT_EQ(trials.size(), 24u);
  for (auto& t : trials) t.pednav_m = run_trial(t.name);
  const GroupFigures orig = figures(trials, true), added = figures(trials, false);
  ASSERT_EQ(orig.trials, 4);
  ASSERT_EQ(added.trials, 20);
  std::printf("[pyshoe auto] original: median %.3fx, worst %.3fx, %d/4 better than one threshold; added: median "
              "%.3fx, worst %.2fx, %d/20 better than one threshold\n",
              orig.median, orig.worst, orig.beats, added.median, added.worst, added.beats);
  EXPECT_LT(orig.median, kOriginalMedianMax);
  EXPECT_LT(orig.worst, kOriginalWorstMax);
  EXPECT_EQ(orig.beats, 4);
  EXPECT_LT(added.median, kAddedMedianMax);
  EXPECT_LT(added.worst, kAddedWorstMax);
  EXPECT_GE(added.beats, kAddedBeatsOneThresholdMin);
}

TEST(DataFootAuto, XioLoopsWithTheSameConfiguration) {
  PEDNAV_REQUIRE_DATA(test::shared_data("foot_xio_ngimu_loops/short_walk.csv"));
  const struct {
    std::string loop;
    double bound, distance_m;
  } loops[] = {{"short", kXioShortClosureMax_m, kXioShortDistance_m},
               {"long", kXioLongClosureMax_m, kXioLongDistance_m}};
  for (const auto& [loop, bound, distance_m] : loops) {
    auto base = load_run_config(test::source_path("datasets/foot/xio_" + loop + ".yaml"));
    ASSERT_TRUE(base) << base.error().message;
    auto cfg = load_run_config(test::source_path("datasets/foot/pyshoe_auto.yaml"));
    ASSERT_TRUE(cfg) << cfg.error().message;
    cfg->imu.file = base->imu.file;  // the log, its format and its place; every filter key from pyshoe_auto.yaml
    cfg->imu.format = base->imu.format;
    cfg->imu.format_preset = base->imu.format_preset;
    cfg->initial = base->initial;
    const auto out = fresh_dir("xio_" + loop);
    auto sum = run_run_command(*cfg, (out / "run").string());
    ASSERT_TRUE(sum) << sum.error().message;
    CompareArgs args;
    args.solution = (out / "run" / "solution.csv").string();
    args.reference = args.solution;
    args.out_dir = (out / "cmp").string();
    args.compare.align = eval::Align::kStart;
    args.compare.loop = true;
    args.plots = false;
    auto ev = run_compare(args);
    ASSERT_TRUE(ev) << ev.error().message;
    std::printf("[xio %s auto] closure %.3f m of %.2f m\n", loop.c_str(), ev->closure_m, ev->distance_m);
    EXPECT_LT(ev->closure_m, bound) << loop;
    EXPECT_NEAR(ev->distance_m, distance_m, kXioDistanceTol_m) << loop;
  }
}

// The trials' own stance labels (`zupt.detector: labels`: PyShoe's detector at its per-trial best threshold) mark the
// stances of two running trials with median lengths of 50 ms (2017-11-27-11-25-12) and 20 ms (2017-11-27-11-13-41).
// At the 20-Hz mechanization rate a stance shorter than the 50-ms interval may hold no interval end; before such a
// stance closed its own interval (ins::zupt_forced_interval_ends, docs/zupt.md §5) those got no ZUPT and the errors
// were 1.123 / 0.396 m. Measured 2026-12-05 with it: 0.1291 / 0.1002 m with 7 / 32 intervals closed early.
// Bounds: measured + 5 %, counts exact.
TEST(DataFootAuto, ShortLabelledStancesKeepTheirZupt) {
  const struct {
    const char* trial;
    double max_m;
    long early_ends;
  } cases[] = {{"2017-11-27-11-25-12", 0.1291 * 1.05, 7}, {"2017-11-27-11-13-41", 0.1002 * 1.05, 32}};
  for (const auto& c : cases)
    PEDNAV_REQUIRE_DATA(test::shared_data(std::string("foot_pyshoe_vicon/csv/") + c.trial + ".csv"));
  for (const auto& c : cases) {
    fusion::EngineSummary sum;
    const double err = run_trial(c.trial, [](RunConfig& cfg) { cfg.zupt.detector = "labels"; }, &sum);
    std::printf("[labels %s] mean horizontal error %.4f m, %ld intervals closed at a short stance\n", c.trial, err,
                sum.zupt_short_stance_interval_ends);
    EXPECT_LE(err, c.max_m) << c.trial;
    EXPECT_EQ(sum.zupt_short_stance_interval_ends, c.early_ends) << c.trial;
  }
}

// The ZUPT-innovation check (docs/fusion.md eq. 15.8) with the minimal configuration: a running trial whose swing errs
// far beyond the self-calibrated model warns, two walks do not. Measured 2026-12-06: 38 of 41 stances beyond χ²₃(0.99)
// (mean first-of-stance NIS 471) on 2017-11-27-11-18-11; 0 of 34 and 0 of 24 on 2018-02-09-11-18-04 and
// 2017-11-22-11-22-03 (mean NIS 0.6 and 2.0). Bounds: the stance counts exact, the share ± 2 stances.
TEST(DataFootAuto, ZuptInnovationsWarnOnARunningTrialOnly) {
  const struct {
    const char* trial;
    long stances, beyond;
    bool warns;
  } cases[] = {{"2017-11-27-11-18-11", 41, 38, true},
               {"2018-02-09-11-18-04", 34, 0, false},
               {"2017-11-22-11-22-03", 24, 0, false}};
  for (const auto& c : cases)
    PEDNAV_REQUIRE_DATA(test::shared_data(std::string("foot_pyshoe_vicon/csv/") + c.trial + ".csv"));
  for (const auto& c : cases) {
    fusion::EngineSummary sum;
    run_trial(c.trial, {}, &sum);
    std::printf("[zupt nis %s] %ld of %ld stances beyond the 99 %% quantile, mean first-of-stance NIS %.1f\n", c.trial,
                sum.zupt_first_nis_above_p99, sum.zupt_first_of_stance,
                sum.zupt_first_nis_sum / std::max(1L, sum.zupt_first_of_stance));
    EXPECT_EQ(sum.zupt_first_of_stance, c.stances) << c.trial;
    EXPECT_NEAR(sum.zupt_first_nis_above_p99, c.beyond, 2) << c.trial;
    std::ifstream in(fresh_dir_path(c.trial) / "run" / "summary.json");
    const std::string summary_text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(summary_text.find("\"zupt_innovations\"") != std::string::npos, c.warns) << c.trial;
  }
}

}  // namespace
}  // namespace pednav::pipeline
