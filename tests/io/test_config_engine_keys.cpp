// SPDX-License-Identifier: BSD-2-Clause
// The filter keys that reach fusion::EngineOptions and round-trip through the resolved configuration (split from
// tests/io/test_config.cpp: elevation weight, scale-factor compensation, ZUPT edges, antenna states and velocity model,
// the heading-frame lever arm, the gyro g-sensitivity, multipath and scale-factor states).
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

// The antenna section: the Doppler rows' velocity model (docs/fusion.md §13), its bad value, and config.resolved.yaml
// (which did not write the section before 2026-12-02) reading back to the same values.
TEST(Config, ElevationWeightKeyReachesTheEngineOptionsAndRoundTrips) {
  const std::string files = "mode: tc\nrover_obs: r.obs\nnav: n.nav\nimu: {file: i.csv, spec: crista}\n";
  auto def = parse(files);
  ASSERT_TRUE(def) << def.error().message;
  EXPECT_DOUBLE_EQ(def->gnss.elevation_weight, 1.0);
  auto cfg = parse(files + "gnss: {elevation_weight: 0.3}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_DOUBLE_EQ(cfg->gnss.elevation_weight, 0.3);
  EXPECT_DOUBLE_EQ(engine_options(*cfg).weights.elevation_weight, 0.3);
  EXPECT_DOUBLE_EQ(engine_options(*def).weights.elevation_weight, 1.0);
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message << "\n" << to_yaml(*cfg);
  EXPECT_DOUBLE_EQ(again->gnss.elevation_weight, 0.3);
  auto bad = parse(files + "gnss: {elevation_weight: 1.5}\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("gnss.elevation_weight"));
  // gnss.code_squaring_loss (eq. W2) the same way.
  EXPECT_DOUBLE_EQ(engine_options(*def).weights.code_squaring_loss, 0.0);
  auto sq = parse(files + "gnss: {code_squaring_loss: 0.002}\n");
  ASSERT_TRUE(sq) << sq.error().message;
  EXPECT_DOUBLE_EQ(engine_options(*sq).weights.code_squaring_loss, 0.002);
  auto sq2 = parse(to_yaml(*sq));
  ASSERT_TRUE(sq2) << sq2.error().message;
  EXPECT_DOUBLE_EQ(sq2->gnss.code_squaring_loss, 0.002);
  auto bad_sq = parse(files + "gnss: {code_squaring_loss: -1}\n");
  ASSERT_FALSE(bad_sq);
  EXPECT_THAT(bad_sq.error().message, HasSubstr("gnss.code_squaring_loss"));
}

TEST(Config, ScaleBiasCompensationKeyReachesTheEngineOptionsAndRoundTrips) {
  const std::string files = "mode: tc\nrover_obs: r.obs\nnav: n.nav\nimu: {file: i.csv, spec: crista}\n";
  auto def = parse(files);
  ASSERT_TRUE(def) << def.error().message;
  EXPECT_TRUE(engine_options(*def).scale_bias_compensation);  // the default since 2026-12-02 (docs/consistency.md §3.6)
  auto cfg = parse(files + "scale_factors: {bias_compensation: false}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_FALSE(engine_options(*cfg).scale_bias_compensation);
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message << "\n" << to_yaml(*cfg);
  EXPECT_FALSE(again->scale_factors.bias_compensation);
  auto bad = parse(files + "scale_factors: {bias_compensation: maybe}\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("scale_factors.bias_compensation"));
}

// zupt.edge_s (docs/zupt.md §5): default 0.02 s, reaches the engine, survives the resolved YAML, range-checked.
TEST(Config, ZuptEdgeKeyReachesTheEngineAndRoundTrips) {
  const std::string files = "mode: tc\nrover_obs: r.obs\nnav: n.nav\nimu: {file: i.csv, spec: crista}\n";
  auto def = parse(files);
  ASSERT_TRUE(def) << def.error().message;
  EXPECT_DOUBLE_EQ(engine_options(*def).zupt_edge_s, 0.02);
  auto cfg = parse(files + "zupt: {edge_s: 0.035}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_DOUBLE_EQ(engine_options(*cfg).zupt_edge_s, 0.035);
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message << "\n" << to_yaml(*cfg);
  EXPECT_DOUBLE_EQ(again->zupt.edge_s, 0.035);
  auto bad = parse(files + "zupt: {edge_s: -0.01}\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("zupt.edge_s: value -0.01 is out of range"));
}

TEST(Config, AntennaStateKeysAndResolvedRoundTrip) {
  // The antenna states' tie at mid-stance and the tight coupling's ratio threshold (docs/carrier.md §8, §10).
  const std::string files = "mode: gnss\nrover_obs: r.obs\nnav: n.nav\n";
  auto def = parse(files);
  ASSERT_TRUE(def) << def.error().message;
  EXPECT_DOUBLE_EQ(def->antenna.stance_sigma_horizontal_m, 0.1);
  EXPECT_DOUBLE_EQ(def->antenna.stance_sigma_vertical_m, 0.1);
  EXPECT_DOUBLE_EQ(def->gnss.ambiguity.tc_ratio_threshold, 4.0);
  auto cfg = parse(files + "antenna: {stance_sigma_horizontal_m: 0.05, stance_sigma_vertical_m: 0.2}\n"
                           "gnss: {ambiguity: {tc_ratio_threshold: 5.5}}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message << "\n" << to_yaml(*cfg);
  EXPECT_DOUBLE_EQ(again->antenna.stance_sigma_horizontal_m, 0.05);
  EXPECT_DOUBLE_EQ(again->antenna.stance_sigma_vertical_m, 0.2);
  EXPECT_DOUBLE_EQ(again->gnss.ambiguity.tc_ratio_threshold, 5.5);
  auto bad = parse(files + "antenna: {stance_sigma_horizontal_m: 0}\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("antenna.stance_sigma_horizontal_m: value 0 is out of range"));
  auto bad_ratio = parse(files + "gnss: {ambiguity: {tc_ratio_threshold: 0.5}}\n");
  ASSERT_FALSE(bad_ratio);
  EXPECT_THAT(bad_ratio.error().message, HasSubstr("gnss.ambiguity.tc_ratio_threshold: value 0.5 is out of range"));
}

TEST(Config, AntennaVelocityModelKeysAndResolvedRoundTrip) {
  const std::string files = "mode: gnss\nrover_obs: r.obs\nnav: n.nav\n";
  auto def = parse(files);
  ASSERT_TRUE(def) << def.error().message;
  EXPECT_EQ(def->antenna.velocity_model, "stride_average");
  auto cfg = parse(files + "antenna:\n  lever_arm_ned_m: [0.1, -0.2, -1.5]\n  velocity_model: foot\n"
                           "  stride_velocity_sigma_horizontal_mps: 0.5\n  stride_velocity_sigma_vertical_mps: 0.2\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->antenna.velocity_model, "foot");
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message << "\n" << to_yaml(*cfg);
  EXPECT_EQ(again->antenna.velocity_model, "foot");
  EXPECT_DOUBLE_EQ(again->antenna.stride_velocity_sigma_horizontal_mps, 0.5);
  EXPECT_DOUBLE_EQ(again->antenna.stride_velocity_sigma_vertical_mps, 0.2);
  EXPECT_DOUBLE_EQ(again->antenna.lever_arm_ned_m.x(), 0.1);
  EXPECT_DOUBLE_EQ(again->antenna.lever_arm_ned_m.z(), -1.5);
  auto bad = parse(files + "antenna: {velocity_model: body}\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message,
              HasSubstr("antenna.velocity_model: expected one of {stride_average, foot}, got 'body'"));
  auto zero = parse(files + "antenna: {stride_velocity_sigma_horizontal_mps: 0}\n");
  ASSERT_FALSE(zero);
  EXPECT_THAT(zero.error().message, HasSubstr("antenna.stride_velocity_sigma_horizontal_mps"));
}

// antenna.lever_arm_heading_m (docs/fusion.md §14): read, reaches the engine, round-trips; default zero; a
// two-element list names the key.
TEST(Config, HeadingFrameLeverArmKeyReachesTheEngineAndRoundTrips) {
  const std::string files = "mode: gnss\nrover_obs: r.obs\nnav: n.nav\n";
  auto def = parse(files);
  ASSERT_TRUE(def) << def.error().message;
  EXPECT_TRUE(engine_options(*def).lever_arm_heading_m.isZero());
  auto cfg = parse(files + "antenna: {lever_arm_heading_m: [0.05, -0.1, 0.02]}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_DOUBLE_EQ(engine_options(*cfg).lever_arm_heading_m.y(), -0.1);
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_DOUBLE_EQ(again->antenna.lever_arm_heading_m.x(), 0.05);
  EXPECT_DOUBLE_EQ(again->antenna.lever_arm_heading_m.y(), -0.1);
  EXPECT_DOUBLE_EQ(again->antenna.lever_arm_heading_m.z(), 0.02);
  auto bad = parse(files + "antenna: {lever_arm_heading_m: [0, -0.1]}\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("antenna.lever_arm_heading_m"));
}

// The gyro g-sensitivity σ of the IMU spec (docs/error_state.md §5): deg/s per g in the file, rad/s per m/s² inside,
// through engine_options to the filter, kept by config.resolved.yaml; a negative value names the key.
TEST(Config, GyroGSensitivitySpecKeyReachesTheEngineAndRoundTrips) {
  const std::string files = "mode: tc\nrover_obs: r.obs\nnav: n.nav\n";
  auto def = parse(files + "imu: {file: i.csv, format: pyshoe, spec: crista}\n");
  ASSERT_TRUE(def) << def.error().message;
  EXPECT_EQ(engine_options(*def).spec.gyro_g_sensitivity, 0.0);
  auto cfg = parse(files + "imu: {file: i.csv, format: pyshoe, spec: {preset: crista, "
                           "gyro_g_sensitivity_deg_per_s_per_g: 0.1}}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  const double expected = 0.1 * kDegToRad / 9.80665;
  EXPECT_NEAR(engine_options(*cfg).spec.gyro_g_sensitivity, expected, 1e-15);
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message << "\n" << to_yaml(*cfg);
  EXPECT_NEAR(again->imu.spec.gyro_g_sensitivity, expected, 1e-12);
  auto bad = parse(files + "imu: {file: i.csv, format: pyshoe, spec: {preset: crista, "
                           "gyro_g_sensitivity_deg_per_s_per_g: -0.1}}\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("gyro_g_sensitivity_deg_per_s_per_g"));
}

TEST(Config, MultipathAndScaleFactorStateKeys) {
  auto cfg = parse(
      "mode: gnss\nrover_obs: r.obs\nnav: n.nav\nmultipath:\n  states: true\n  sigma_m: 0.5\n  tau_s: 30\n"
      "  slots: 10\nscale_factors:\n  states: true\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_TRUE(cfg->multipath.states);
  EXPECT_DOUBLE_EQ(cfg->multipath.sigma_m, 0.5);
  EXPECT_DOUBLE_EQ(cfg->multipath.tau_s, 30.0);
  EXPECT_EQ(cfg->multipath.slots, 10);
  EXPECT_EQ(cfg->scale_factors.states, std::optional<bool>(true));
  // The resolved configuration carries them (config.resolved.yaml reads back to the same values).
  auto again = parse(to_yaml(*cfg));
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_TRUE(again->multipath.states);
  EXPECT_EQ(again->multipath.slots, 10);
  EXPECT_EQ(again->scale_factors.states, std::optional<bool>(true));
  auto bad = parse("mode: gnss\nrover_obs: r.obs\nnav: n.nav\nmultipath:\n  slots: 40\n  tau_s: 0\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("multipath.slots: value 40 is out of range"));
  EXPECT_THAT(bad.error().message, HasSubstr("multipath.tau_s: value 0 is out of range"));
}

}  // namespace
}  // namespace pednav::io

namespace pednav::io {
namespace {

}  // namespace
}  // namespace pednav::io
