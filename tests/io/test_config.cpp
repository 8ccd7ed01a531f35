// SPDX-License-Identifier: BSD-2-Clause
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cctype>
#include <stdexcept>

#include "core/geodesy.hpp"
#include "io/config.hpp"
#include "io/yaml_schema.hpp"
#include "pipeline/run_command.hpp"

namespace pednav::io {
namespace {

using pipeline::engine_options;  // RunConfig -> fusion::EngineOptions (pipeline/run_command.hpp)

using ::testing::HasSubstr;

Expected<RunConfig> parse(const std::string& text) { return parse_run_config(text, "cfg.yaml", "/data/run"); }

TEST(Config, MinimalGnssConfigResolvesPaths) {
  auto cfg = parse("mode: gnss\nrover_obs: rover.obs\nbase_obs: /abs/base.obs\nnav: [a.nav, ../b.nav]\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->gnss.rover_obs, "/data/run/rover.obs");
  EXPECT_EQ(cfg->gnss.base_obs, "/abs/base.obs");
  ASSERT_EQ(cfg->gnss.nav.size(), 2u);
  EXPECT_EQ(cfg->gnss.nav[1], "/data/b.nav");
  EXPECT_DOUBLE_EQ(cfg->mechanization_rate_hz, 20.0);
  EXPECT_EQ(cfg->zupt.form, "D");
}

TEST(Config, UnknownKeyIsAnErrorWithPathAndLine) {
  auto cfg = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\ngnss:\n  elevation_mask: 10\n");
  ASSERT_FALSE(cfg);
  EXPECT_THAT(cfg.error().message, HasSubstr("cfg.yaml:5: gnss.elevation_mask: unknown key"));
}

// yaml-cpp reads the first of two equal keys; a second `gnss:` appended to a file must not be silently ignored.
TEST(Config, DuplicateKeyIsAnErrorNamingBothLines) {
  auto top = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\ngnss:\n  elevation_mask_deg: 10\ngnss:\n  min_cn0_dbhz: 20\n");
  ASSERT_FALSE(top);
  EXPECT_THAT(top.error().message, HasSubstr("cfg.yaml:6: gnss: duplicate key (first at line 4)"));
  auto nested = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\ngnss:\n  min_cn0_dbhz: 10\n  min_cn0_dbhz: 20\n");
  ASSERT_FALSE(nested);
  EXPECT_THAT(nested.error().message, HasSubstr("cfg.yaml:6: gnss.min_cn0_dbhz: duplicate key (first at line 5)"));
}

// gnss.ambiguity.glonass_ifb (docs/carrier.md §3.1): search by default, off accepted, anything else named with its line.
TEST(Config, GlonassIfbIsSearchOrOff) {
  auto def = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\n");
  ASSERT_TRUE(def) << def.error().message;
  EXPECT_EQ(def->gnss.ambiguity.glonass_ifb, "search");
  auto off = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\ngnss:\n  ambiguity: {glonass_ifb: off}\n");
  ASSERT_TRUE(off) << off.error().message;
  EXPECT_EQ(off->gnss.ambiguity.glonass_ifb, "off");
  auto bad = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\ngnss:\n  ambiguity:\n    glonass_ifb: calibrate\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message,
              HasSubstr("cfg.yaml:6: gnss.ambiguity.glonass_ifb: expected one of {search, off}, got 'calibrate'"));
}

TEST(Config, WrongTypeNegativeRateAndBadEnumAreAllReportedAtOnce) {
  auto cfg = parse(
      "mode: gnss\nrover_obs: r.obs\nnav: n.nav\nmechanization_rate_hz: -5\n"
      "gnss:\n  elevation_mask_deg: ten\nzupt:\n  form: E\nsmoother:\n  enabled: maybe\n");
  ASSERT_FALSE(cfg);
  const std::string& m = cfg.error().message;
  EXPECT_THAT(m, HasSubstr("cfg.yaml:4: mechanization_rate_hz: value -5 is out of range"));
  EXPECT_THAT(m, HasSubstr("gnss.elevation_mask_deg: expected a finite number, got 'ten'"));
  EXPECT_THAT(m, HasSubstr("zupt.form: expected one of {D, F}, got 'E'"));
  EXPECT_THAT(m, HasSubstr("smoother.enabled: expected true or false, got 'maybe'"));
}

TEST(Config, MissingRequiredKeysDependOnMode) {
  auto gnss = parse("mode: gnss\n");
  ASSERT_FALSE(gnss);
  EXPECT_THAT(gnss.error().message, HasSubstr("rover_obs: required key is missing (mode gnss)"));
  EXPECT_THAT(gnss.error().message, HasSubstr("nav: required key is missing (mode gnss)"));
  auto ins = parse("mode: ins\n");
  ASSERT_FALSE(ins);
  EXPECT_THAT(ins.error().message, HasSubstr("imu: required key is missing (mode ins)"));
  auto imu_without_file = parse("mode: ins\nimu:\n  format: pyshoe\n");
  ASSERT_FALSE(imu_without_file);
  EXPECT_THAT(imu_without_file.error().message, HasSubstr("imu.file: required key is missing"));
}

TEST(Config, BasePositionMustBeEcef) {
  auto cfg = parse("mode: gnss\nrover_obs: r\nnav: n\nbase_position_ecef_m: [53.2, -9.0, 66.8]\n");
  ASSERT_FALSE(cfg);
  EXPECT_THAT(cfg.error().message, HasSubstr("base_position_ecef_m: is not an ECEF position"));
  auto ok = parse("mode: gnss\nrover_obs: r\nnav: n\nbase_position_ecef_m: [3774085.6456, -601662.5769, 5089316.3970]\n");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_NEAR(ok->gnss.base_position_ecef_m->y(), -601662.5769, 1e-9);
}

TEST(Config, SyntaxErrorAndEmptyAndMissingFile) {
  auto bad = parse("mode: [gnss\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("cfg.yaml:"));
  EXPECT_THAT(bad.error().message, HasSubstr("YAML syntax error"));
  auto empty = parse("");
  ASSERT_FALSE(empty);
  EXPECT_THAT(empty.error().message, HasSubstr("cfg.yaml: configuration is empty"));
  auto missing = load_run_config("/nonexistent/dir/run.yaml");
  ASSERT_FALSE(missing);
  EXPECT_THAT(missing.error().message, HasSubstr("/nonexistent/dir/run.yaml: cannot open configuration file"));
  auto not_a_map = parse("- a\n- b\n");
  ASSERT_FALSE(not_a_map);
  EXPECT_THAT(not_a_map.error().message, HasSubstr("(top level): expected a mapping"));
}

TEST(Config, ResolvedYamlParsesBackToTheSameConfig) {
  auto cfg = parse(
      "mode: tc\nrover_obs: r.obs\nnav: [n.nav]\nimu:\n  file: imu.csv\n  spec: crista\n"
      "gnss:\n  systems: [G, R]\n  elevation_mask_deg: 15\nzupt:\n  form: F\nsmoother:\n  enabled: false\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  auto again = parse_run_config(to_yaml(*cfg), "resolved.yaml", "/elsewhere");
  ASSERT_TRUE(again) << again.error().message << "\n" << to_yaml(*cfg);
  EXPECT_EQ(again->gnss.rover_obs, "/data/run/r.obs");
  EXPECT_EQ(again->gnss.systems, (std::vector<std::string>{"G", "R"}));
  EXPECT_NEAR(again->gnss.elevation_mask_rad, cfg->gnss.elevation_mask_rad, 1e-12);
  EXPECT_EQ(again->zupt.form, "F");
  EXPECT_FALSE(again->smoother_enabled);
  EXPECT_EQ(again->imu.spec_preset, "crista");
}

}  // namespace
}  // namespace pednav::io

namespace pednav::io {
namespace {

using pipeline::engine_options;  // RunConfig -> fusion::EngineOptions (pipeline/run_command.hpp)

TEST(Config, AccelOnlyScaleStatesAndBiasModelKeys) {
  auto cfg = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\nscale_factors:\n  states: true\n  gyro: false\n"
                   "bias:\n  model: random_walk\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->scale_factors.states, std::optional<bool>(true));
  EXPECT_FALSE(cfg->scale_factors.gyro);
  EXPECT_EQ(cfg->bias.model, "random_walk");
  auto again = parse(to_yaml(*cfg));  // config.resolved.yaml reads back to the same values
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_FALSE(again->scale_factors.gyro);
  EXPECT_EQ(again->bias.model, "random_walk");
  auto bad = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\nbias:\n  model: rw\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message,
              HasSubstr("bias.model: expected one of {auto, gauss_markov, random_walk}, got 'rw'"));
  bad = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\nscale_factors:\n  states: maybe\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("scale_factors.states: expected one of {auto, true, false}, got 'maybe'"));
}

// The defaults depend on the mode (docs/consistency.md §3.3, §3.16): tc gets scale-factor states and the random-walk
// bias model, ins the scale-factor states only for an uncalibrated (≥ 1 %) gyro; explicit keys win; the resolved configuration writes what was used.
TEST(Config, ImuErrorModelDefaultsDependOnTheMode) {
  const std::string files = "rover_obs: r.obs\nnav: n.nav\nimu: {file: i.csv, format: pyshoe, spec: crista}\n";
  auto tc = parse("mode: tc\n" + files);
  ASSERT_TRUE(tc) << tc.error().message;
  EXPECT_FALSE(tc->scale_factors.states.has_value());
  EXPECT_EQ(tc->bias.model, "auto");
  ImuErrorModelChoice m = imu_error_model_choice(*tc);
  EXPECT_TRUE(m.scale_states);
  EXPECT_TRUE(m.gyro_scale_states);  // both blocks since 2026-12-02 (docs/consistency.md §3.4)
  EXPECT_TRUE(m.bias_random_walk);
  auto tc_acc = parse("mode: tc\n" + files + "scale_factors: {gyro: false}\n");
  ASSERT_TRUE(tc_acc) << tc_acc.error().message;
  m = imu_error_model_choice(*tc_acc);
  EXPECT_TRUE(m.scale_states);
  EXPECT_FALSE(m.gyro_scale_states);
  auto ins = parse("mode: ins\n" + files);  // crista: gyro scale-factor σ 1 %, uncalibrated (§3.16)
  ASSERT_TRUE(ins) << ins.error().message;
  m = imu_error_model_choice(*ins);
  EXPECT_TRUE(m.scale_states);
  EXPECT_TRUE(m.gyro_scale_states);
  EXPECT_FALSE(m.bias_random_walk);
  auto ins_calibrated = parse("mode: ins\nimu: {file: i.csv, format: pyshoe, spec: ngimu}\n");  // 0.5 %
  ASSERT_TRUE(ins_calibrated) << ins_calibrated.error().message;
  m = imu_error_model_choice(*ins_calibrated);
  EXPECT_FALSE(m.scale_states);
  EXPECT_FALSE(m.bias_random_walk);
  auto tc_off = parse("mode: tc\n" + files + "scale_factors: {states: false}\nbias: {model: gauss_markov}\n");
  ASSERT_TRUE(tc_off) << tc_off.error().message;
  m = imu_error_model_choice(*tc_off);
  EXPECT_FALSE(m.scale_states);
  EXPECT_FALSE(m.bias_random_walk);
  auto ins_on = parse("mode: ins\n" + files + "scale_factors: {states: true}\nbias: {model: random_walk}\n");
  ASSERT_TRUE(ins_on) << ins_on.error().message;
  m = imu_error_model_choice(*ins_on);
  EXPECT_TRUE(m.scale_states);
  EXPECT_TRUE(m.gyro_scale_states);  // an explicit `states: true` keeps gyro's own default (true)
  EXPECT_TRUE(m.bias_random_walk);
  auto again = parse(to_yaml(*tc));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_EQ(again->scale_factors.states, std::optional<bool>(true));
  EXPECT_TRUE(again->scale_factors.gyro);
  EXPECT_EQ(again->bias.model, "random_walk");
}

// config.resolved.yaml keeps an imu.spec map's overrides (it used to write the preset name only, losing them).
TEST(Config, ResolvedConfigurationKeepsImuSpecOverrides) {
  const std::string files = "rover_obs: r.obs\nnav: n.nav\n";
  auto cfg = parse("mode: tc\n" + files +
                   "imu: {file: i.csv, format: pyshoe, spec: {preset: crista, gyro_range_deg_per_s: 2000, "
                   "accel_scale_ppm: 0}}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message << "\n" << to_yaml(*cfg);
  EXPECT_DOUBLE_EQ(again->imu.spec.gyro_range, 2000.0 * kDegToRad);
  EXPECT_EQ(again->imu.spec.accel_scale_sigma, 0.0);
  EXPECT_DOUBLE_EQ(again->imu.spec.gyro_arw, cfg->imu.spec.gyro_arw);
  EXPECT_EQ(again->imu.spec_preset, "crista");
  // A plain preset is written as its name.
  auto plain = parse("mode: tc\n" + files + "imu: {file: i.csv, format: pyshoe, spec: crista}\n");
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_THAT(to_yaml(*plain), HasSubstr("spec: crista"));
}

// `imu.spec: auto` and `zupt.shoe_threshold: auto` (docs/ins.md §10, docs/zupt.md §6): parsed as flags resolved from
// the log at run time; config.resolved.yaml of a run without a log reads back; a misspelt value names its key.
TEST(Config, AutoSpecAndAutoThresholdAreFlagsAndMisspellingsAreNamed) {
  const std::string base = "mode: ins\nimu:\n  file: imu.csv\n  format: pyshoe\n  spec: auto\n"
                           "initial: {lat_deg: 45, lon_deg: 0, h_m: 0, yaw_deg: 0}\n";
  auto cfg = parse(base + "zupt:\n  shoe_threshold: auto\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_TRUE(cfg->imu.spec_auto);
  EXPECT_TRUE(cfg->imu.has_spec);
  EXPECT_TRUE(cfg->zupt.shoe_threshold_auto);
  EXPECT_FALSE(cfg->zupt.edge_s_given);
  EXPECT_FALSE(cfg->zupt.zaru_gate_given);
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_TRUE(again->imu.spec_auto);
  auto given = parse(base + "zupt:\n  shoe_threshold: auto\n  edge_s: 0.02\n  zaru_gate_probability: 0\n");
  ASSERT_TRUE(given) << given.error().message;
  EXPECT_TRUE(given->zupt.edge_s_given);
  EXPECT_TRUE(given->zupt.zaru_gate_given);
  EXPECT_DOUBLE_EQ(cfg->zupt.shoe_threshold_motion, 2.5);  // ins::AutoThresholdOptions' allowance
  auto motion = parse(base + "zupt:\n  shoe_threshold: auto\n  shoe_threshold_motion: 4\n");
  ASSERT_TRUE(motion) << motion.error().message;
  EXPECT_DOUBLE_EQ(motion->zupt.shoe_threshold_motion, 4.0);
  auto fixed = parse(base + "zupt:\n  shoe_threshold: 3\n  shoe_threshold_motion: 2.5\n");
  ASSERT_FALSE(fixed);
  EXPECT_THAT(fixed.error().message, HasSubstr("zupt.shoe_threshold_motion: only used with shoe_threshold: auto"));
  EXPECT_DOUBLE_EQ(cfg->zupt.shoe_threshold_two_class_cap, 10.0);  // ins::AutoThresholdOptions' cap
  auto cap = parse(base + "zupt:\n  shoe_threshold: auto\n  shoe_threshold_two_class_cap: 0\n");
  ASSERT_TRUE(cap) << cap.error().message;
  EXPECT_DOUBLE_EQ(cap->zupt.shoe_threshold_two_class_cap, 0.0);
  auto fixed_cap = parse(base + "zupt:\n  shoe_threshold: 3\n  shoe_threshold_two_class_cap: 5\n");
  ASSERT_FALSE(fixed_cap);
  EXPECT_THAT(fixed_cap.error().message,
              HasSubstr("zupt.shoe_threshold_two_class_cap: only used with shoe_threshold: auto"));
  auto negative_cap = parse(base + "zupt:\n  shoe_threshold: auto\n  shoe_threshold_two_class_cap: -1\n");
  ASSERT_FALSE(negative_cap);
  EXPECT_THAT(negative_cap.error().message, HasSubstr("zupt.shoe_threshold_two_class_cap"));
  auto bad = parse(base + "zupt:\n  shoe_threshold: automatic\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("zupt.shoe_threshold"));
  bad = parse("mode: ins\nimu:\n  file: imu.csv\n  format: pyshoe\n  spec: autox\n"
              "initial: {lat_deg: 45, lon_deg: 0, h_m: 0, yaw_deg: 0}\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("unknown IMU spec preset 'autox'"));
}

}  // namespace
}  // namespace pednav::io

namespace pednav::io {
namespace {

// `step_velocity:` and `zupt.updates` (seed 000 aiding): parsed, written to config.resolved.yaml, bad values named.
TEST(Config, StepVelocityKeysRoundTripAndBadValuesAreNamed) {
  const std::string base = "mode: ins\nimu:\n  file: imu.csv\n  format: pyshoe\n  spec: gx5_25\n"
                           "initial: {lat_deg: 45, lon_deg: 0, h_m: 0, yaw_deg: 0}\n";
  auto cfg = parse(base + "zupt:\n  updates: false\nstep_velocity:\n  enabled: true\n  leg_length_m: 2.96\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_TRUE(cfg->step_velocity.enabled);
  EXPECT_DOUBLE_EQ(cfg->step_velocity.leg_length_m, 2.96);
  EXPECT_FALSE(cfg->zupt.updates);
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_TRUE(again->step_velocity.enabled);
  EXPECT_DOUBLE_EQ(again->step_velocity.leg_length_m, 2.96);
  EXPECT_FALSE(again->zupt.updates);
  auto bad = parse(base + "step_velocity:\n  min_step_s: 2\n  max_step_s: 1\n  leg: 1\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("step_velocity.max_step_s: must be > min_step_s"));
  EXPECT_THAT(bad.error().message, HasSubstr("step_velocity.leg"));
}

// config.resolved.yaml carries the initial state a run used (a mode-ins run needs it to be rerun from that file).
TEST(Config, InitialSectionRoundTrips) {
  const std::string base = "mode: ins\nimu:\n  file: imu.csv\n  format: lord_sensorconnect\n  spec: gx5_25\n";
  auto mag = parse(base + "initial: {lat_deg: 45, lon_deg: 7, h_m: 300, heading: magnetometer, declination_deg: 2.5, "
                          "sigma_yaw_deg: 20, sigma_position_m: 0.5}\n");
  ASSERT_TRUE(mag) << mag.error().message;
  auto again = parse(to_yaml(*mag));
  ASSERT_TRUE(again) << again.error().message;
  ASSERT_TRUE(again->initial.position_e.has_value());
  EXPECT_LT((*again->initial.position_e - *mag->initial.position_e).norm(), 1e-6);
  EXPECT_TRUE(again->initial.heading_from_magnetometer);
  EXPECT_NEAR(again->initial.declination_rad, mag->initial.declination_rad, 1e-12);
  EXPECT_NEAR(again->initial.sigma_yaw_rad, mag->initial.sigma_yaw_rad, 1e-12);
  EXPECT_DOUBLE_EQ(again->initial.sigma_position_m, 0.5);
  EXPECT_FALSE(again->initial.yaw_rad.has_value());
  auto yaw = parse(base + "initial: {lat_deg: 45, lon_deg: 7, h_m: 300, yaw_deg: -30}\n");
  ASSERT_TRUE(yaw) << yaw.error().message;
  auto yaw_again = parse(to_yaml(*yaw));
  ASSERT_TRUE(yaw_again) << yaw_again.error().message;
  ASSERT_TRUE(yaw_again->initial.yaw_rad.has_value());
  EXPECT_NEAR(*yaw_again->initial.yaw_rad, *yaw->initial.yaw_rad, 1e-12);
  EXPECT_FALSE(yaw_again->initial.heading_from_magnetometer);
}

// The resolved configuration writes each number as the shortest decimal that reads back to the same double: 0.1, not
// yaml-cpp's 0.10000000000000001 (issue 49 item 6).
TEST(Config, ResolvedNumbersAreTheShortestThatReadBack) {
  auto cfg = parse(
      "mode: gnss\nrover_obs: r.obs\nnav: n.nav\nbase_position_ecef_m: [3774085.6456, -601662.5769, "
      "5089316.397]\ngnss: {code_sigma_zenith_m: 0.1, epoch_match_tolerance_s: 0.3}\n"
      "antenna: {lever_arm_ned_m: [0.1, -0.2, -1.3]}\nzupt: {edge_s: 0.07}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  const std::string y = to_yaml(*cfg);
  EXPECT_THAT(y, HasSubstr("code_sigma_zenith_m: 0.1\n")) << y;
  EXPECT_THAT(y, HasSubstr("epoch_match_tolerance_s: 0.3\n")) << y;
  EXPECT_THAT(y, HasSubstr("edge_s: 0.07\n")) << y;
  EXPECT_THAT(y, HasSubstr("lever_arm_ned_m: [0.1, -0.2, -1.3]")) << y;
  EXPECT_THAT(y, HasSubstr("base_position_ecef_m: [3774085.6456, -601662.5769, 5089316.397]")) << y;
  // Every number is the shortest decimal of its double (keys in degrees: the shortest the reader turns back into
  // the same radians, yaml_degrees), so no 17-digit form is left.
  for (size_t b = 0; b < y.size();) {
    const size_t e = y.find_first_of(" ,[]\n", b);
    const std::string tok = y.substr(b, e == std::string::npos ? std::string::npos : e - b);
    b = e == std::string::npos ? y.size() : e + 1;
    if (tok.empty() || !(std::isdigit(static_cast<unsigned char>(tok[0])) || tok[0] == '-')) continue;
    size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(tok, &used);
    } catch (const std::exception&) {
      continue;
    }
    if (used != tok.size()) continue;
    EXPECT_EQ(tok, yaml_number(v)) << "not the shortest form:\n" << y;
  }
  EXPECT_THAT(y, HasSubstr("hmm_grade_width_deg_per_s: 60\n")) << y;
  EXPECT_EQ(yaml_degrees(60.0 * kDegToRad), "60");
  EXPECT_EQ(yaml_degrees(60.0 * 3.14159265358979323846 / 180.0), "60");
  EXPECT_EQ(std::stod(yaml_degrees(1.5)) * kDegToRad, 1.5);
  // Shortest, yet exact: every value reads back bit for bit.
  auto again = parse(y);
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_EQ(again->gnss.code_sigma_zenith_m, cfg->gnss.code_sigma_zenith_m);
  EXPECT_EQ(again->gnss.elevation_mask_rad, cfg->gnss.elevation_mask_rad);
  EXPECT_EQ(again->antenna.lever_arm_ned_m, cfg->antenna.lever_arm_ned_m);
  EXPECT_EQ(*again->gnss.base_position_ecef_m, *cfg->gnss.base_position_ecef_m);
  EXPECT_EQ(again->zupt.edge_s, cfg->zupt.edge_s);
  EXPECT_EQ(yaml_number(0.1), "0.1");
  EXPECT_EQ(yaml_number(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(std::stod(yaml_number(1.0 / 3.0)), 1.0 / 3.0);
  EXPECT_EQ(yaml_number(-2.5e-7), "-2.5e-07");
  EXPECT_EQ(yaml_number(1e300 * 1e300), ".inf");
}

// An inline IMU column map is written into the resolved configuration (it was left out, so config-check did not show
// it and config.resolved.yaml could not be rerun) and reads back to the same format.
TEST(Config, ResolvedConfigurationEchoesTheInlineImuFormat) {
  auto cfg = parse(
      "mode: ins\nimu:\n  file: imu.csv\n  spec: crista\n  format:\n    delimiter: tab\n    header_lines: 2\n"
      "    time: {base: gps_sow, column: 1, unit: ms, gps_week: 2100}\n"
      "    gyro: {columns: [4, 5, 6], unit: deg_per_s, signs: [1, -1, -1], full_scale_deg_per_s: 2000}\n"
      "    accel: {columns: [7, 8, 9], unit: g, full_scale_g: 16}\n    stance: {column: 10}\n"
      "    mag: {columns: [11, 12, 13], unit: gauss}\n    mounting_rpy_deg: [0, 0, 90]\n    max_gap_s: 0.25\n"
      "initial: {lat_deg: 45, lon_deg: 7, h_m: 300, yaw_deg: 0}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  const std::string y = to_yaml(*cfg);
  EXPECT_THAT(y, HasSubstr("columns: [7, 8, 9]")) << y;
  EXPECT_THAT(y, HasSubstr("delimiter: tab")) << y;
  auto again = parse(y);
  ASSERT_TRUE(again) << again.error().message << "\n" << y;
  const ImuFormat &a = cfg->imu.format, &b = again->imu.format;
  EXPECT_EQ(b.name, "inline");
  EXPECT_EQ(b.delimiter, '\t');
  EXPECT_EQ(b.header_lines, 2);
  EXPECT_EQ(b.time_base, "gps_sow");
  EXPECT_EQ(b.time_column, 1);
  EXPECT_EQ(b.time_scale_s, 1e-3);
  EXPECT_EQ(b.gps_week, 2100);
  EXPECT_EQ(b.gyro_columns, a.gyro_columns);
  EXPECT_EQ(b.accel_columns, a.accel_columns);
  EXPECT_EQ(b.gyro_signs, a.gyro_signs);
  EXPECT_EQ(b.gyro_unit, "deg_per_s");
  EXPECT_EQ(b.accel_unit, "g");
  EXPECT_DOUBLE_EQ(b.gyro_full_scale, a.gyro_full_scale);
  EXPECT_DOUBLE_EQ(b.accel_full_scale, a.accel_full_scale);
  EXPECT_EQ(b.stance_column, 10);
  EXPECT_EQ(b.mag_columns, a.mag_columns);
  EXPECT_EQ(b.mag_scale_to_ut, 100.0);
  EXPECT_EQ(b.R_b_s, a.R_b_s);
  EXPECT_THAT(y, HasSubstr("mounting_rpy_deg: [0, 0, 90]")) << "the angles as given";
  EXPECT_EQ(b.max_gap_s, 0.25);
  EXPECT_EQ(b.gap_factor, a.gap_factor);
  EXPECT_EQ(b.rest_tolerance_mps2, a.rest_tolerance_mps2);
  // A preset is written as its name.
  auto preset = parse("mode: ins\nimu: {file: imu.csv, format: pyshoe, spec: crista}\n");
  ASSERT_TRUE(preset) << preset.error().message;
  EXPECT_THAT(to_yaml(*preset), HasSubstr("format: pyshoe\n"));
}

// Integer keys take whole numbers inside their range; anything else is named with its key path (never cast).
TEST(Config, IntegerKeysAreRangeChecked) {
  auto big = parse(
      "mode: gnss\nrover_obs: r\nnav: n\nfault_rejection: {window_epochs: 1e71}\n"
      "multipath: {slots: 2.5}\n");
  ASSERT_FALSE(big);
  EXPECT_THAT(big.error().message, HasSubstr("cfg.yaml:4: fault_rejection.window_epochs: value 1e71 is out of range"));
  EXPECT_THAT(big.error().message, HasSubstr("cfg.yaml:5: multipath.slots: expected an integer, got '2.5'"));
  auto list = parse("mode: gnss\nrover_obs: r\nnav: n\nreference: {file: ref.nmea, nmea_qualities: 4}\n");
  ASSERT_FALSE(list);
  EXPECT_THAT(list.error().message, HasSubstr("reference.nmea_qualities: expected a list of integers, got '4'"));
  auto ok = parse("mode: gnss\nrover_obs: r\nnav: n\nreference: {file: ref.nmea, nmea_qualities: [4, 5]}\n");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->reference.nmea_qualities, (std::vector<int>{4, 5}));
}

}  // namespace
}  // namespace pednav::io
