// SPDX-License-Identifier: BSD-2-Clause
// A foot IMU nobody tuned pednav to (issue 37; datasets/unknown_sensor.yaml): seed 004's indoor loops with the sensor
// mounted z axis up and rolled 30° about the foot's long axis, a 0.5 °/s turn-on gyro bias σ, 3× the Crista's white
// noise, 500 Hz. `pednav calibrate` must recover what it can see, and `imu.spec: auto` + `zupt.shoe_threshold: auto`
// must close the loop (docs/ins.md §10, docs/zupt.md §6).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include <algorithm>

#include <cstdio>
#include <filesystem>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "io/scenario_config.hpp"
#include "pipeline/calibrate_command.hpp"
#include "pipeline/compare_command.hpp"
#include "pipeline/run_command.hpp"
#include "pipeline/self_calibration.hpp"
#include "pipeline/simulate_command.hpp"
#include "sim/simulator.hpp"
#include "tests/sim/fixtures.hpp"
#include "tests/support/data.hpp"

namespace pednav {
namespace {

// Measured 2026-12-06 (Release, this scenario, seed 4137): closure 0.33 % of 188 m, horizontal RMS 0.40 m against the
// truth. The same log with the configuration `pednav simulate` writes (the Crista preset, SHOE γ 10, which happens to
// be the sensor's own family) closes at 0.54 % with an RMS of 1.35 m; with the first auto threshold design (a factor
// of the rest level) 7-18 %. Bounds: the 1 % closure; the RMS at the measured 0.40 m + 30 % (runs are
// deterministic; the margin is for another libm), which the non-auto configuration does not meet.
constexpr double kMaxClosurePct = 1.0;
constexpr double kMaxRms_m = 0.40 * 1.30;
constexpr double kMeasuredClosurePct = 0.33, kMeasuredDistance_m = 187.9;  // closure bound + 30 %, distance ±1 %
// Calibration, measured 2026-12-05: ARW 18.30 / 18.02 / 17.61 deg/√h against the simulated 18, VRW 0.3537 / 0.3521 /
// 0.3531 m/s/√h against 0.353; +z up, tilt 30.204°. Beside the issue's ±20 %: each axis within ±3 % of its measured
// figure (an estimate from one seeded log: deterministic; 3 % lets the still-period windows move by one), the
// tilt within ±0.1°.
constexpr double kNoiseTolerance = 0.2;  // issue 37: noise density within 20 %
constexpr double kArwMeasured_deg_per_sqrt_h[3] = {18.30, 18.02, 17.61};
constexpr double kVrwMeasured_mps_per_sqrt_h[3] = {0.3537, 0.3521, 0.3531};
constexpr double kMeasuredNoiseTolerance = 0.03;
constexpr double kTiltMeasured_deg = 30.204;

// `pednav compare --loop` of DIR/run/solution.csv against DIR/truth.csv (no plots).
Expected<eval::Evaluation> compare_loop(const std::string& dir) {
  pipeline::CompareArgs args;
  args.solution = dir + "/run/solution.csv";
  args.reference = dir + "/truth.csv";
  args.out_dir = dir + "/cmp";
  args.compare.loop = true;
  args.plots = false;
  return pipeline::run_compare(args);
}

TEST(UnknownSensor, CalibrateRecoversTheSensorAndAutoClosesTheLoop) {
  auto file = io::load_scenario(test::source_path("datasets/unknown_sensor.yaml"));
  ASSERT_TRUE(file) << file.error().message;
  const std::string dir = test::temp_dir("unknown_sensor");
  ASSERT_TRUE(pipeline::run_simulate_command(*file, dir).has_value());
  auto truth_sim = sim::simulate(file->scenario);  // the same seed: the truth of the written files
  ASSERT_TRUE(truth_sim) << truth_sim.error().message;

  auto cfg = io::load_run_config(dir + "/config.yaml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  auto cal = pipeline::run_calibrate_command(*cfg, dir + "/cal");
  ASSERT_TRUE(cal) << cal.error().message;
  const ins::ImuCalibration& c = cal->self.calibration;
  EXPECT_NEAR(c.rate_hz, 500.0, 1e-6);
  EXPECT_EQ(c.up_axis, "+z");
  EXPECT_NEAR(c.tilt_deg, 30.0, 1.0);
  ASSERT_TRUE(c.bias_estimated);
  // The truth at the first sample, on the sensor axes: turn-on bias + drift + the Earth rate.
  const Eigen::Matrix3d R_b_s = file->scenario.imu.R_b_s;
  const Eigen::Vector3d earth_s = R_b_s.transpose() * truth_sim->truth.nav.front().R_e_b().transpose() *
                                  Eigen::Vector3d(0.0, 0.0, wgs84::kOmegaIE_radps);
  const Eigen::Vector3d b_true = truth_sim->imu_errors.b_g_first + earth_s;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(c.gyro_bias_radps(i), b_true(i), 3.0 * c.gyro_bias_sd_radps(i)) << "axis " << i;
  }
  const double arw_true = 18.0 * kDegToRad / 60.0, vrw_true = 0.353 / 60.0;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(c.gyro_noise_density(i), arw_true, kNoiseTolerance * arw_true) << "axis " << i;
    EXPECT_NEAR(c.accel_noise_density(i), vrw_true, kNoiseTolerance * vrw_true) << "axis " << i;
    const double arw = c.gyro_noise_density(i) * kRadToDeg * 60.0, vrw = c.accel_noise_density(i) * 60.0;
    EXPECT_NEAR(arw, kArwMeasured_deg_per_sqrt_h[i], kMeasuredNoiseTolerance * kArwMeasured_deg_per_sqrt_h[i]) << i;
    EXPECT_NEAR(vrw, kVrwMeasured_mps_per_sqrt_h[i], kMeasuredNoiseTolerance * kVrwMeasured_mps_per_sqrt_h[i]) << i;
  }
  EXPECT_NEAR(c.tilt_deg, kTiltMeasured_deg, 0.1);

  std::printf("[unknown sensor, calibrate] tilt %.3f deg; ARW %.2f %.2f %.2f deg/sqrt(h); VRW %.4f %.4f %.4f m/s/sqrt(h)\n",
              c.tilt_deg, c.gyro_noise_density(0) * kRadToDeg * 60.0, c.gyro_noise_density(1) * kRadToDeg * 60.0,
              c.gyro_noise_density(2) * kRadToDeg * 60.0, c.accel_noise_density(0) * 60.0,
              c.accel_noise_density(1) * 60.0, c.accel_noise_density(2) * 60.0);
  cfg->imu.spec_auto = true;
  cfg->zupt.shoe_threshold_auto = true;
  // `zupt.shoe_threshold_motion` is the allowance above the rest level, and `auto` switches on the cross-validated
  // gait-adaptive raise (ins::kAutoAdaptive*) unless it is configured.
  {
    auto log = io::read_imu_csv(cfg->imu.file, cfg->imu.format);
    ASSERT_TRUE(log) << log.error().message;
    io::RunConfig a = *cfg, b = *cfg, c0 = *cfg;
    b.zupt.shoe_threshold_motion = 4.0;
    c0.zupt.shoe_threshold_two_class_cap = 0.0;
    const auto sa = pipeline::resolve_self_calibration(a, *log), sb = pipeline::resolve_self_calibration(b, *log),
               sc = pipeline::resolve_self_calibration(c0, *log);
    ASSERT_TRUE(sa && sb && sc);
    // This log's two-class split (measured: the level at rest + 3.01) lies above rest + 2.5 and below the cap 10:
    // γ is the split (docs/zupt.md eq. 6.2); with an allowance of 4, rest + 4 is above the split; without the split
    // (cap 0), rest + 2.5.
    EXPECT_TRUE(sa->threshold.from_split);
    EXPECT_DOUBLE_EQ(sa->threshold.threshold, std::min(sa->threshold.split, 10.0));
    EXPECT_GT(sa->threshold.threshold, sa->threshold.rest + 2.5);
    EXPECT_FALSE(sb->threshold.from_split);
    EXPECT_NEAR(sb->threshold.threshold - sb->threshold.rest, 4.0, 1e-12);
    EXPECT_FALSE(sc->threshold.from_split);
    EXPECT_NEAR(sc->threshold.threshold - sc->threshold.rest, 2.5, 1e-12);
    EXPECT_DOUBLE_EQ(a.zupt.shoe_threshold, sa->threshold.threshold);
    EXPECT_DOUBLE_EQ(a.zupt.shoe_adaptive_factor, ins::kAutoAdaptiveFactor);
    EXPECT_NEAR(a.zupt.shoe_adaptive_min_peak_radps, ins::kAutoAdaptiveMinPeakDegPerS * kDegToRad, 1e-12);
  }
  auto sum = pipeline::run_run_command(*cfg, dir + "/run");
  ASSERT_TRUE(sum) << sum.error().message;
  auto ev = compare_loop(dir);
  ASSERT_TRUE(ev) << ev.error().message;
  std::printf("[unknown sensor, auto] closure %.3f m = %.2f %% of %.1f m, RMS %.3f m\n", ev->closure_m,
              ev->closure_pct_of_distance, ev->distance_m, ev->horizontal_rms_m);
  EXPECT_LT(ev->closure_pct_of_distance, kMaxClosurePct);  // issue 37
  EXPECT_LT(ev->closure_pct_of_distance, 1.3 * kMeasuredClosurePct);
  EXPECT_NEAR(ev->distance_m, kMeasuredDistance_m, 0.01 * kMeasuredDistance_m);
  EXPECT_LT(ev->horizontal_rms_m, kMaxRms_m);
  // The run's fit warnings (docs/fusion.md §15).
  std::ifstream js(dir + "/run/summary.json");
  const auto summary = nlohmann::json::parse(js);
  std::string codes;
  for (const auto& w : summary["warnings"]) codes += w["code"].get<std::string>() + " (" + w["message"].get<std::string>() + ") ";
  std::printf("[unknown sensor, auto] warnings: %s\n", codes.empty() ? "none" : codes.c_str());
  // None today: the smoother moves this INS-only track by decimetres, well inside the metres of σ the forward and
  // smoothed solutions carry here, so eq. 15.1 does not see the misfit (docs/fusion.md §15); the gait checks pass.
  EXPECT_TRUE(codes.empty());

  // config.resolved.yaml repeats the run that wrote it, from its own folder: the self-calibrated IMU model, the
  // auto threshold with its gait-adaptive raise and the ZARU noise, the input paths made absolute (its zupt
  // section used to keep only the detector and form, so a rerun used γ 10 and no raise: 0.38 m RMS instead of 0.62).
  auto resolved = io::load_run_config(dir + "/run/config.resolved.yaml");
  ASSERT_TRUE(resolved) << resolved.error().message;
  ASSERT_TRUE(pipeline::run_run_command(*resolved, dir + "/rerun").has_value());
  for (const char* f : {"solution.csv", "smoothed.csv", "config.resolved.yaml"}) {
    EXPECT_EQ(test::read_text(dir + "/run/" + f), test::read_text(dir + "/rerun/" + f)) << f;
  }
}

// The same scenario drawn with seed 2: its accelerometer is 0.51 m/s² off 1 g at rest (the simulated turn-on bias),
// which calibration and levelling used to take for motion (|f| − g beyond 0.5 m/s²): no still period, no gyro bias
// from the log, and the loop closed at 11.1 % (RMS 14.1 m). With the 1.5 m/s² tolerance of a consumer accelerometer
// (ins::CalibrationOptions, ins::StillnessOptions) measured 2026-12-06: closure 0.71 % of 188 m, RMS 0.74 m.
// Bounds: the measured figures + 30 % (deterministic; the margin is for another libm), both far below the old ones.
TEST(UnknownSensor, AnAccelerometerOffOneGAtRestStillCalibratesAndClosesTheLoop) {
  auto file = io::load_scenario(test::source_path("datasets/unknown_sensor.yaml"));
  ASSERT_TRUE(file) << file.error().message;
  file->scenario.seed = 2;
  const std::string dir = test::temp_dir("unknown_sensor_seed2");
  ASSERT_TRUE(pipeline::run_simulate_command(*file, dir).has_value());
  auto cfg = io::load_run_config(dir + "/config.yaml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  cfg->imu.spec_auto = true;  // the minimal configuration: no spec, no threshold
  cfg->zupt.shoe_threshold_auto = true;
  auto sum = pipeline::run_run_command(*cfg, dir + "/run");
  ASSERT_TRUE(sum) << sum.error().message;
  std::ifstream js(dir + "/run/summary.json");
  const auto summary = nlohmann::json::parse(js);
  EXPECT_TRUE(summary["self_calibration"]["calibration"]["bias_estimated"].get<bool>());
  auto ev = compare_loop(dir);
  ASSERT_TRUE(ev) << ev.error().message;
  std::printf("[unknown sensor, seed 2] closure %.2f %% of %.1f m, RMS %.3f m\n", ev->closure_pct_of_distance,
              ev->distance_m, ev->horizontal_rms_m);
  EXPECT_LT(ev->closure_pct_of_distance, 0.71 * 1.3);
  EXPECT_LT(ev->horizontal_rms_m, 0.74 * 1.3);
  EXPECT_NEAR(ev->distance_m, kMeasuredDistance_m, 0.01 * kMeasuredDistance_m);
}

}  // namespace
}  // namespace pednav

namespace pednav {
namespace {

struct MinimalRun {
  eval::Evaluation ev;
  std::string warnings;
};

// `pednav simulate` of a scenario, then the minimal configuration (no imu.spec, no zupt.shoe_threshold: both from the
// log) and `pednav compare --loop` of the forward solution against the truth.
MinimalRun run_minimal(const std::string& scenario, const std::string& name) {
  MinimalRun out;
  auto file = io::load_scenario(test::source_path(scenario));
  EXPECT_TRUE(file) << file.error().message;
  if (!file) return out;
  const std::string dir = test::temp_dir(name);
  EXPECT_TRUE(pipeline::run_simulate_command(*file, dir).has_value());
  {  // the written configuration without its `spec:` line, as a user with this sensor would start
    std::ifstream in(dir + "/config.yaml");
    std::ofstream minimal(dir + "/minimal.yaml");
    for (std::string line; std::getline(in, line);) {
      if (line.find("  spec:") != 0) minimal << line << "\n";
    }
  }
  auto cfg = io::load_run_config(dir + "/minimal.yaml");
  EXPECT_TRUE(cfg) << cfg.error().message;
  if (!cfg) return out;
  EXPECT_TRUE(cfg->imu.spec_auto && cfg->zupt.shoe_threshold_auto);
  auto sum = pipeline::run_run_command(*cfg, dir + "/run");
  EXPECT_TRUE(sum) << sum.error().message;
  auto ev = compare_loop(dir);
  EXPECT_TRUE(ev) << ev.error().message;
  if (ev) out.ev = *ev;
  std::ifstream js(dir + "/run/summary.json");
  const auto summary = nlohmann::json::parse(js);
  for (const auto& w : summary["warnings"]) out.warnings += w["code"].get<std::string>() + " ";
  return out;
}

// Issue 49's second unknown sensor: 60 Hz (sample times rounded to the nanosecond), z down, 3x the Crista's noise,
// 0.5 °/s turn-on bias σ (datasets/unknown_sensor_60hz.yaml, seed 6060). Measured 2026-12-06: closure 0.47 % of
// 188 m, RMS 1.31 m (start as configured). Over seeds 1-8 as well (scripts/unknown_sensors): median 1.13 %, worst
// 4.29 %, <= 1 % on 4 of 9 — the 1 % holds on this seed, not on every draw (docs/results.md). Bounds: the
// measured figures + 30 %.
TEST(UnknownSensor, SixtyHertzZDownClosesTheLoopWithTheMinimalConfiguration) {
  const MinimalRun r = run_minimal("datasets/unknown_sensor_60hz.yaml", "unknown_sensor_60hz");
  std::printf("[unknown sensor 60 Hz] closure %.2f %% of %.1f m, RMS %.3f m; warnings: %s\n",
              r.ev.closure_pct_of_distance, r.ev.distance_m, r.ev.horizontal_rms_m,
              r.warnings.empty() ? "none" : r.warnings.c_str());
  EXPECT_LT(r.ev.closure_pct_of_distance, 0.47 * 1.3);
  EXPECT_LT(r.ev.horizontal_rms_m, 1.31 * 1.3);
  EXPECT_EQ(r.warnings, "");
  EXPECT_NEAR(r.ev.distance_m, 189.0, 0.01 * 189.0);  // this draw's strides
}

// The third: 1000 Hz, turned 90° in yaw on the foot, 1 °/s turn-on bias σ (datasets/unknown_sensor_1000hz.yaml, seed
// 1000). The configuration's start yaw is the foot's, so only the closure is scored. Measured 2026-12-06: 2.76 % of
// 188 m — the 1 % is NOT met on this draw (seeds 1-8: median 1.07 %, worst 2.76 %, <= 1 % on 3 of 9); the run
// warns forward_smoothed_disagree (6.0 % of the epochs beyond 99 %). Bound: the measured closure + 30 %.
TEST(UnknownSensor, ThousandHertzTurnedNinetyDegreesClosesTheLoopWithTheMinimalConfiguration) {
  const MinimalRun r = run_minimal("datasets/unknown_sensor_1000hz.yaml", "unknown_sensor_1000hz");
  std::printf("[unknown sensor 1000 Hz] closure %.2f %% of %.1f m; warnings: %s\n", r.ev.closure_pct_of_distance,
              r.ev.distance_m, r.warnings.empty() ? "none" : r.warnings.c_str());
  EXPECT_EQ(r.warnings, "forward_smoothed_disagree ");  // the misfit is reported
  EXPECT_LT(r.ev.closure_pct_of_distance, 2.76 * 1.3);
  EXPECT_NEAR(r.ev.distance_m, 193.2, 0.01 * 193.2);  // this draw's strides
}

}  // namespace
}  // namespace pednav
