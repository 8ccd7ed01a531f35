// SPDX-License-Identifier: BSD-2-Clause
// INS/ZUPT (`mode: ins`) on real foot data with the committed configurations of datasets/foot/ (issue 5):
// x-io short loop closure, the mean start-aligned horizontal error of the four PyShoe Vicon trials, and the error of
// LORD #35 at its footprints. Each bound is the figure measured on 2026-12-05 (Release build) plus a stated margin
// (docs/conventions.md "Test bounds"), so a regression shows; the targets are checked beside them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <optional>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/calibrate_command.hpp"
#include "pipeline/compare_command.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "tests/support/data.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::pipeline {
namespace {

using namespace pednav::io;

// Margins: the runs are deterministic on one platform; another libm/compiler moves a figure by round-off that the
// filter can amplify. Closures and mean errors of a few centimetres get +30 % (the widest of the 5–30 % range: a
// centimetre-level figure is the difference of two long tracks), the larger RMS / max / footprint errors +20 %,
// counts ±5 %.
constexpr double kMarginSmall = 1.30;
constexpr double kMarginLarge = 1.20;
constexpr double kMarginCount = 0.05;

// x-io short_walk, shoe gamma 10, form D. Measured 2026-12-05: closure 0.0231 m of a 26.70 m path, 492 ZUPT updates
// (x-io's own ZUPT result: 0.082 m; x-io README: about 25 m). 2.10 m before the initial heading σ was carried outside
// the filter (docs/fusion.md §5.5), so the closure bound fails without it; a detector that loses stances inflates the
// path (29.9 m before §5.5).
constexpr double kXioShortClosure_m = 0.0231;
constexpr double kXioShortDistance_m = 26.70;
constexpr double kXioShortDistanceTol_m = 0.5;  // ±2 % of the path: a lost or extra stride moves it by about 1 m
constexpr long kXioShortZuptUpdates = 492;
// PyShoe trials, same configuration (one for the GX5-25: PyShoe's process noise, SHOE γ 1.5, gait-adaptive α 3 next to
// a swing, every stance sample, ZARU gate; docs/results.md "INS/ZUPT on real foot data"), mean horizontal error after
// start alignment. Issue targets (PyShoe tuned per trial): 0.045 / 0.132 / 0.112 / 0.047 m. Measured 2026-12-05 in
// the table below (mean 0.0460 / 0.1171 / 0.0962 / 0.0435 m): trial 1 misses its target by 1 mm since a stance
// shorter than the 50-ms mechanization interval keeps its ZUPT (ins::zupt_forced_interval_ends: one 45-ms stance at
// 9.26 s, the foot turning on the spot, Vicon still; 0.0438 m without that update), the other three are met. With
// the GX5-25 configuration before 2026-12-04 (the data-sheet process noise, the adaptive threshold without the swing
// condition): 0.091 / 0.613 / 2.781 / 0.114 m. Each target fails without the change it guards (re-measured with γ 1.5): with γ 3 (the threshold
// until 2026-12-04) trials 1 / 4 are 0.050 / 0.051 m; without the swing condition trial 4 is 0.846 m; with the
// data-sheet noise 0.110 / 0.528 / 1.186 / 0.119 m; with α 2 trial 3 is 0.472 m; with the 0.02-s stance-edge skip
// trial 1 is 0.051 m; without the ZARU gate trial 1 is 0.127 m; when the first still period's mean rate is taken as
// the gyro bias although the foot rolled in it (docs/ins.md eq. 6.1) trial 1 is 0.061 m.
constexpr double kPyshoeWalk1Target_m = 0.045;
constexpr double kPyshoeWalk2Target_m = 0.132;
constexpr double kPyshoeRunTarget_m = 0.112;
constexpr double kPyshoeTarget_m = 0.047;
// With PyShoe's own stance labels (zupt.detector labels), i.e. the INS/ZUPT on PyShoe's stances (0.058 m on trial
// 2017-11-22-11-22-03 with the rolled still period's mean as the gyro bias, 0.126 m on the 2018 trial with the
// data-sheet process noise). PyShoe's own INS on these stances: 0.045 / 0.047 m (the targets).

// Figures of one PyShoe run measured on 2026-12-05: mean / RMS / max horizontal error [m], compared epochs, stance
// samples (the detector's, or the labels'), labelled stance samples in the log.
struct PyshoeMeasured {
  const char* trial;
  const char* detector;  // "" = as configured
  double mean_m, rms_m, max_m;
  int epochs;
  long stance_samples, labelled;
  double target_m;
  bool target_met;  // false: the target is not met (printed and bounded by the measurement only)
};
constexpr PyshoeMeasured kPyshoeMeasured[] = {
    {"2017-11-22-11-22-03", "", 0.0460, 0.0781, 0.8561, 648, 1620, 1780, kPyshoeWalk1Target_m, false},
    {"2017-11-22-11-30-14", "", 0.1171, 0.1417, 0.8336, 897, 1922, 3019, kPyshoeWalk2Target_m, true},
    {"2017-11-27-11-25-12", "", 0.0962, 0.1102, 0.2553, 749, 1570, 1515, kPyshoeRunTarget_m, true},
    {"2018-02-09-11-19-39", "", 0.0435, 0.0545, 0.1537, 1539, 6498, 6320, kPyshoeTarget_m, true},
    {"2017-11-22-11-22-03", "labels", 0.0411, 0.0732, 0.8625, 648, 1780, 1780, kPyshoeWalk1Target_m, true},
    {"2018-02-09-11-19-39", "labels", 0.0433, 0.0545, 0.1517, 1539, 6320, 6320, kPyshoeTarget_m, true},
};
// LORD #35 (fast walk, 29 footprints), same GX5-25 configuration: RMS error at the footprints measured 1.2031 m
// (2026-12-05; final 3.3 % of the path). 1.19 m with γ 3, 1.25 m before the still-period bias check (2026-12-04);
// 31.6 m with the GX5-25 configuration before 2026-12-04; with γ 1.5: 12.2 m with α 2, 17.6 m with the data-sheet
// noise, 5.03 m without the ZARU gate.
constexpr double kLordFastWalkRms_m = 1.2031;

std::filesystem::path temp_dir(const std::string& name) {
  const auto d = test::temp_dir_path("data_foot_ins_" + name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// Runs `cfg` into out/run and compares its solution.csv with `reference` (start-aligned; the solution itself when
// empty, as a loop) into out/cmp. Failures are test failures; nullopt then.
struct RunAndCompare {
  fusion::EngineSummary summary;
  eval::Evaluation evaluation;
};

std::optional<RunAndCompare> run_and_compare(const RunConfig& cfg, const std::filesystem::path& out,
                                             const std::string& reference) {
  auto sum = run_run_command(cfg, (out / "run").string());
  EXPECT_TRUE(sum) << sum.error().message;
  if (!sum) return std::nullopt;
  CompareArgs args;
  args.solution = (out / "run" / "solution.csv").string();
  args.reference = reference.empty() ? args.solution : reference;
  args.out_dir = (out / "cmp").string();
  args.compare.align = eval::Align::kStart;
  args.compare.loop = reference.empty();
  auto ev = run_compare(args);
  EXPECT_TRUE(ev) << ev.error().message;
  if (!ev) return std::nullopt;
  return RunAndCompare{*sum, *ev};
}

// An x-io loop with the committed configuration (detector replaced unless empty): the solution against itself,
// closure = first-to-last horizontal distance.
struct XioLoop {
  double closure_m = 1e9, distance_m = 0.0;
  long zupt_updates = 0;
  bool covariance_healthy = false;
};

XioLoop run_xio_loop(const std::string& loop, const std::string& detector) {
  XioLoop r;
  auto cfg = load_run_config(test::source_path("datasets/foot/xio_" + loop + ".yaml"));
  EXPECT_TRUE(cfg) << cfg.error().message;
  if (!cfg) return r;
  if (!detector.empty()) cfg->zupt.detector = detector;
  const auto out = temp_dir("xio_" + loop + "_" + (detector.empty() ? "configured" : detector));
  const auto rc = run_and_compare(*cfg, out, "");
  if (!rc) return r;
  r.zupt_updates = static_cast<long>(rc->summary.zupt_updates);
  r.covariance_healthy = rc->summary.covariance_healthy;
  const eval::Evaluation& ev = rc->evaluation;
  r.closure_m = ev.closure_m;
  r.distance_m = ev.distance_m;
  return r;
}

TEST(DataFootIns, XioShortLoopClosure) {
  PEDNAV_REQUIRE_DATA(test::shared_data("foot_xio_ngimu_loops/short_walk.csv"));
  const XioLoop r = run_xio_loop("short", "");
  EXPECT_TRUE(r.covariance_healthy);
  std::printf("[xio short] closure %.4f m of %.2f m, ZUPT updates %ld\n", r.closure_m, r.distance_m, r.zupt_updates);
  EXPECT_LT(r.closure_m, kMarginSmall * kXioShortClosure_m);
  EXPECT_NEAR(r.distance_m, kXioShortDistance_m, kXioShortDistanceTol_m);
  EXPECT_NEAR(static_cast<double>(r.zupt_updates), kXioShortZuptUpdates, kMarginCount * kXioShortZuptUpdates);
}

// Issue 8: with the HMM detector the end-point error of both x-io loops is no worse than with SHOE at its default
// threshold. Measured 2026-12-06: short 0.0156 (HMM) vs 0.0231 m (SHOE), long 0.0839 vs 0.1220 m; each bounded by
// its figure +30 % (kMarginSmall). Before the refined HMM stance kept every still part of a decoded stance
// (docs/zupt.md §3), 0.170 and 0.168 m: the test fails without it.
TEST(DataFootIns, XioHmmClosureIsNoWorseThanShoe) {
  PEDNAV_REQUIRE_DATA(test::shared_data("foot_xio_ngimu_loops/short_walk.csv"));
  PEDNAV_REQUIRE_DATA(test::shared_data("foot_xio_ngimu_loops/long_walk.csv"));
  struct Measured {
    const char* loop;
    double hmm_m, shoe_m;
  };
  for (const Measured m : {Measured{"short", 0.0156, 0.0231}, Measured{"long", 0.0839, 0.1220}}) {
    const std::string loop = m.loop;
    const double hmm = run_xio_loop(loop, "hmm").closure_m, shoe = run_xio_loop(loop, "shoe").closure_m;
    std::printf("[xio %s] closure hmm %.4f m, shoe %.4f m\n", loop.c_str(), hmm, shoe);
    EXPECT_LE(hmm, shoe) << loop;
    EXPECT_LT(hmm, kMarginSmall * m.hmm_m) << loop;
    EXPECT_LT(shoe, kMarginSmall * m.shoe_m) << loop;
  }
}

// A PyShoe trial with the committed configuration (detector replaced unless empty), scored against its Vicon
// truth after start alignment.
struct PyshoeTrial {
  double mean_m = 1e9, rms_m = 1e9, max_m = 1e9;
  int epochs = 0;
  long zupt_samples = 0, labelled_stance_samples = 0;
  double still_gyro_bias_d2 = -1.0, initial_gyro_bias_deg_per_h = -1.0;  // summary.json (norm of the vector)
};

PyshoeTrial run_pyshoe_trial(const std::string& trial, const std::string& detector) {
  PyshoeTrial r;
  const std::string log = test::shared_data("foot_pyshoe_vicon/csv/" + trial + ".csv");
  const auto out = temp_dir("pyshoe_" + trial + "_" + (detector.empty() ? "configured" : detector));
  // Reference as scripts/foot_reference writes it: gps_week 0, tow = the log's seconds, e = gt_y, n = gt_x
  // (the stored Vicon x, y, z-up axes are mirrored w.r.t. a right-handed frame; docs/results.md).
  {
    std::ifstream in(log);
    std::ofstream ref(out / "ref.csv");
    std::string line;
    std::getline(in, line);  // header: t_s, 6 IMU columns, gt_x_m, gt_y_m, gt_z_m, label
    ref << "gps_week,gps_tow_s,e_m,n_m,u_m\n";
    while (std::getline(in, line)) {
      std::stringstream ss(line);
      std::string cell[11];
      for (auto& c : cell) std::getline(ss, c, ',');
      ref << "0," << cell[0] << ',' << cell[8] << ',' << cell[7] << ',' << cell[9] << '\n';
      r.labelled_stance_samples += cell[10] == "1";
    }
  }
  auto cfg = load_run_config(test::source_path("datasets/foot/pyshoe_vicon_" + trial + ".yaml"));
  EXPECT_TRUE(cfg) << cfg.error().message;
  if (!cfg) return r;
  if (!detector.empty()) cfg->zupt.detector = detector;
  const auto rc = run_and_compare(*cfg, out, (out / "ref.csv").string());
  if (!rc) return r;
  r.zupt_samples = static_cast<long>(rc->summary.zupt_samples);
  {
    std::ifstream js(out / "run" / "summary.json");
    const auto j = nlohmann::json::parse(js, nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << trial;
    if (!j.is_discarded()) {
      r.still_gyro_bias_d2 = j.value("still_gyro_bias_d2", -1.0);
      const auto b = j.value("initial_gyro_bias_deg_per_h", std::vector<double>{});
      if (b.size() == 3) r.initial_gyro_bias_deg_per_h = std::hypot(b[0], b[1], b[2]);
    }
  }
  const eval::Evaluation& ev = rc->evaluation;
  r.mean_m = ev.horizontal_mean_m;
  r.rms_m = ev.horizontal_rms_m;
  r.max_m = ev.horizontal_max_m;
  r.epochs = ev.epochs_compared;
  std::printf("[pyshoe %s %s] mean %.4f m, RMS %.4f m, max %.4f m over %d epochs; stance samples %ld (labelled %ld)\n",
              trial.c_str(), detector.empty() ? "configured" : detector.c_str(), r.mean_m, r.rms_m, r.max_m, r.epochs,
              r.zupt_samples, r.labelled_stance_samples);
  // Every printed figure against its measurement (kPyshoeMeasured) and the target.
  const PyshoeMeasured* m = nullptr;
  for (const auto& x : kPyshoeMeasured)
    if (trial == x.trial && detector == x.detector) m = &x;
  EXPECT_NE(m, nullptr) << trial << " " << detector << ": no measured figures";
  if (!m) return r;
  if (m->target_met) {
    EXPECT_LT(r.mean_m, m->target_m) << trial << " (issue target)";
  }
  EXPECT_LT(r.mean_m, kMarginSmall * m->mean_m) << trial;
  EXPECT_LT(r.rms_m, kMarginLarge * m->rms_m) << trial;
  EXPECT_LT(r.max_m, kMarginLarge * m->max_m) << trial;
  EXPECT_NEAR(r.epochs, m->epochs, kMarginCount * m->epochs) << trial;
  EXPECT_NEAR(static_cast<double>(r.zupt_samples), m->stance_samples, kMarginCount * m->stance_samples) << trial;
  EXPECT_EQ(r.labelled_stance_samples, m->labelled) << trial;  // read from the log: exact
  return r;
}

TEST(DataFootIns, PyshoeTrialMeanError) {
  for (const std::string trial :
       {"2017-11-22-11-22-03", "2017-11-22-11-30-14", "2017-11-27-11-25-12", "2018-02-09-11-19-39"}) {
    PEDNAV_REQUIRE_DATA(test::shared_data("foot_pyshoe_vicon/csv/" + trial + ".csv"));
    const PyshoeTrial r = run_pyshoe_trial(trial, "");  // checks the figures against kPyshoeMeasured
    if (trial == "2017-11-22-11-22-03") {  // the foot rolls before its first step: the window's mean is not the bias
      EXPECT_GT(r.still_gyro_bias_d2, 16.27);
      EXPECT_EQ(r.initial_gyro_bias_deg_per_h, 0.0);
    }
    if (trial == "2018-02-09-11-19-39") {  // 12.6 s still: taken (measured d² 0.3, 82 deg/h)
      EXPECT_LT(r.still_gyro_bias_d2, 16.27);
      EXPECT_GT(r.initial_gyro_bias_deg_per_h, 0.0);
    }
  }
}

// A LORD hallway log (SensorConnectData_<number>) run with `cfg` and scored at the measured footprints as
// scripts/foot_eval does: reference = footprint k at the end of stance k (the stride time file), start-aligned; the
// solution epoch nearest each footprint time (within 0.05 s) gives the error there. The RMS over the footprints (and
// their count in `n`); failures are test failures (1e9 then).
double lord_footprint_rms(const std::string& number, const RunConfig& cfg, int& n) {
  n = 0;
  const std::string base = test::shared_data("foot_lord_gcp_hallway/SensorConnectData_" + number);
  const auto out = temp_dir("lord_" + number);
  std::vector<double> times;
  {
    std::ifstream st(base + "_strideIndex_timestamp_gcpX_gcpY.csv"), gcp(base + "_GCP.csv");
    std::ofstream ref(out / "ref.csv");
    ref << "gps_week,gps_tow_s,e_m,n_m,u_m\n";
    std::string a, b;
    std::getline(st, a);
    std::getline(gcp, b);
    while (std::getline(st, a) && std::getline(gcp, b)) {
      std::stringstream sa(a), sb(b);
      std::string idx, t, stride, x, y;
      std::getline(sa, idx, ',');
      std::getline(sa, t, ',');
      std::getline(sb, stride, ',');
      std::getline(sb, x, ',');
      std::getline(sb, y, ',');
      times.push_back(std::stod(t));
      ref << "0," << t << ',' << x << ',' << y << ",0\n";
    }
  }
  if (!run_and_compare(cfg, out, (out / "ref.csv").string())) return 1e9;
  std::vector<std::pair<double, double>> rows;  // (tow, horizontal error)
  {
    std::ifstream in(out / "cmp" / "errors.csv");
    std::string line;
    std::getline(in, line);  // gps_week,gps_tow_s,de_m,dn_m,du_m,horizontal_m
    while (std::getline(in, line)) {
      std::stringstream ss(line);
      std::string c[6];
      for (auto& x : c) std::getline(ss, x, ',');
      rows.emplace_back(std::stod(c[1]), std::stod(c[5]));
    }
  }
  double sum_sq = 0.0;
  for (const double t : times) {
    const auto near = std::min_element(rows.begin(), rows.end(), [t](const auto& p, const auto& q) {
      return std::abs(p.first - t) < std::abs(q.first - t);
    });
    if (near == rows.end() || std::abs(near->first - t) > 0.05) continue;
    sum_sq += near->second * near->second;
    ++n;
  }
  EXPECT_EQ(static_cast<size_t>(n), times.size()) << "footprints without a solution epoch";
  return n > 0 ? std::sqrt(sum_sq / n) : 1e9;
}

// LORD hallway experiment 35 with the committed configuration at its 29 footprints.
TEST(DataFootIns, LordFastWalkErrorAtTheFootprints) {
  PEDNAV_REQUIRE_DATA(test::shared_data("foot_lord_gcp_hallway/SensorConnectData_35.csv"));
  auto cfg = load_run_config(test::source_path("datasets/foot/lord_35.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  int n = 0;
  const double rms_m = lord_footprint_rms("35", *cfg, n);
  std::printf("[lord 35] RMS at %d footprints %.4f m\n", n, rms_m);
  ASSERT_EQ(n, 29);
  EXPECT_LT(rms_m, kMarginLarge * kLordFastWalkRms_m);
}

// LORD #34 with the minimal configuration (pyshoe_auto.yaml's filter keys: imu.spec and the threshold from the log;
// its own file, format and start). Its first 1.5 s read 2302 deg/h and the accelerometer shows gravity turning with
// that rate in the sensor axes (docs/ins.md eq. 10.2, k 1.3): the foot was settling, not still. Measured 2026-12-06:
// footprint RMS 0.397 m (the committed gx5_25 configuration: 0.326 m); 0.845 m when the auto spec's turn-on σ covered
// that reading (the run then started from a 0.6 deg/s "bias"). Bound: the measured figure + 5 %, below the old one.
constexpr double kLord34MinimalRms_m = 0.397;

TEST(DataFootIns, LordWalkWithTheMinimalConfigurationSettlingFootIsNotABias) {
  PEDNAV_REQUIRE_DATA(test::shared_data("foot_lord_gcp_hallway/SensorConnectData_34.csv"));
  auto base = load_run_config(test::source_path("datasets/foot/lord_34.yaml"));
  ASSERT_TRUE(base) << base.error().message;
  auto cfg = load_run_config(test::source_path("datasets/foot/pyshoe_auto.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  cfg->imu.file = base->imu.file;
  cfg->imu.format = base->imu.format;
  cfg->imu.format_preset = base->imu.format_preset;
  cfg->initial = base->initial;
  int n = 0;
  const double rms_m = lord_footprint_rms("34", *cfg, n);
  std::printf("[lord 34 minimal] RMS at %d footprints %.4f m\n", n, rms_m);
  ASSERT_EQ(n, 25);
  EXPECT_LT(rms_m, 1.05 * kLord34MinimalRms_m);
  std::ifstream js(test::temp_dir_path("data_foot_ins_lord_34") / "run" / "summary.json");
  const auto summary = nlohmann::json::parse(js);
  const auto& window = summary["self_calibration"]["calibration"]["bias_window"];
  EXPECT_TRUE(window["moving"].get<bool>());
  EXPECT_NEAR(window["rotation_k"].get<double>(), 1.3, 0.2);
  EXPECT_LT(summary["self_calibration"]["spec"]["gyro_bias_initial_deg_per_s"].get<double>(), 0.021);
  // `pednav calibrate` says so: the one-line summary, the warning and the comment of calibration.yaml's σ.
  auto cal = run_calibrate_command(*cfg, (test::temp_dir_path("data_foot_ins_lord_34_cal")).string());
  ASSERT_TRUE(cal) << cal.error().message;
  EXPECT_NE(cal->summary.find("first still period turning at [-0.438, 0.445, 0.138] deg/s"), std::string::npos)
      << cal->summary;
  std::ifstream y(test::temp_dir_path("data_foot_ins_lord_34_cal") / "calibration.yaml");
  const std::string yaml((std::istreambuf_iterator<char>(y)), std::istreambuf_iterator<char>());
  EXPECT_NE(yaml.find("gyro_bias_initial_deg_per_s: 0.02  # the first still period turned"), std::string::npos) << yaml;
}

// zupt.detector labels with the pyshoe format's stance column: the stance is exactly PyShoe's stored labels (its
// SHOE at the threshold it tuned per trial against the Vicon truth), so the INS/ZUPT error is separated from the
// detector's (figures in kPyshoeMeasured). The stance-sample count fails if the labels were ignored.
TEST(DataFootIns, PyshoeTrialWithPyshoesOwnStanceLabels) {
  for (const std::string trial : {"2017-11-22-11-22-03", "2018-02-09-11-19-39"}) {
    PEDNAV_REQUIRE_DATA(test::shared_data("foot_pyshoe_vicon/csv/" + trial + ".csv"));
    const PyshoeTrial r = run_pyshoe_trial(trial, "labels");  // checks the figures against kPyshoeMeasured
    EXPECT_EQ(r.zupt_samples, r.labelled_stance_samples) << trial;
  }
}

}  // namespace
}  // namespace pednav::pipeline
