// SPDX-License-Identifier: BSD-2-Clause
// `pednav simulate` outputs (pipeline/simulate_command.*): same seed -> byte-identical files; a different seed
// changes them; config.yaml loads as a run configuration pointing at the written files; config_datasheet.yaml
// loads to the scenario's own sensor models.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "pipeline/simulate_command.hpp"
#include "sim/gnss_sim.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav {
namespace {

const char* kFiles[] = {"truth.csv", "imu.csv", "rover.obs", "base.obs", "nav.rnx", "blunders.csv", "config.yaml",
                        "config_datasheet.yaml"};

io::ScenarioFile short_walk(uint64_t seed) {
  auto f = test::scenario_from_text(test::kOpenSkyGnssYaml);
  f.scenario.seed = seed;
  f.scenario.waypoints.resize(3);  // one lap's first two legs
  f.scenario.gnss.blunder_rate = 0.01;
  return f;
}

TEST(SimulateCommand, SameSeedGivesByteIdenticalFiles) {
  const std::string a = test::temp_dir("sim_a"), b = test::temp_dir("sim_b"), c = test::temp_dir("sim_c");
  ASSERT_TRUE(pipeline::run_simulate_command(short_walk(7), a).has_value());
  ASSERT_TRUE(pipeline::run_simulate_command(short_walk(7), b).has_value());
  ASSERT_TRUE(pipeline::run_simulate_command(short_walk(8), c).has_value());
  for (const char* f : kFiles) {
    const std::string ta = test::read_text(a + "/" + f), tb = test::read_text(b + "/" + f);
    ASSERT_FALSE(ta.empty()) << f;
    EXPECT_TRUE(ta == tb) << f << " differs between two runs with the same seed";
  }
  EXPECT_NE(test::read_text(a + "/imu.csv"), test::read_text(c + "/imu.csv"));
  EXPECT_NE(test::read_text(a + "/rover.obs"), test::read_text(c + "/rover.obs"));
  for (const auto& e : std::filesystem::directory_iterator(a))  // no temporary leftovers
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
}

TEST(SimulateCommand, ConfigYamlIsARunConfigurationOnTheWrittenFiles) {
  const std::string d = test::temp_dir("sim_cfg");
  ASSERT_TRUE(pipeline::run_simulate_command(short_walk(3), d).has_value());
  auto cfg = io::load_run_config(d + "/config.yaml");
  ASSERT_TRUE(cfg.has_value()) << (cfg ? "" : cfg.error().message);
  EXPECT_EQ(cfg->mode, "tc") << "the main job's mode (issue 49 item 8)";
  EXPECT_TRUE(std::filesystem::exists(cfg->gnss.rover_obs)) << cfg->gnss.rover_obs;
  EXPECT_TRUE(std::filesystem::exists(cfg->gnss.base_obs));
  ASSERT_EQ(cfg->gnss.nav.size(), 1u);
  EXPECT_TRUE(cfg->gnss.base_position_ecef_m.has_value());
  EXPECT_TRUE(std::filesystem::exists(cfg->imu.file));
  EXPECT_EQ(cfg->imu.format.time_base, "gps_sow");
  EXPECT_EQ(cfg->imu.spec_preset, "crista");
  EXPECT_TRUE(std::filesystem::exists(cfg->reference.file));
  EXPECT_EQ(cfg->reference.format, "csv");
}

TEST(SimulateCommand, DataSheetConfigLoadsToTheScenarioSensorModels) {
  // Values unlike pednav run's defaults, so that a part the writer leaves out fails the test.
  io::ScenarioFile f = short_walk(3);
  f.scenario.imu.gyro_g_sensitivity_sigma = 0.13 * kDegToRad / 9.80665;  // 0.13 °/s/g
  f.scenario.gnss.multipath_sigma_m = 0.37;
  f.scenario.gnss.multipath_tau_s = 12.5;
  f.scenario.gnss.multipath_cn0_ref_dbhz = 43.0;
  f.scenario.gait.foot_offset_m = 0.12;
  const sim::Scenario& sc = f.scenario;
  const std::string d = test::temp_dir("sim_ds");
  ASSERT_TRUE(pipeline::run_simulate_command(f, d).has_value());
  auto plain = io::load_run_config(d + "/config.yaml");
  auto ds = io::load_run_config(d + "/config_datasheet.yaml");
  ASSERT_TRUE(plain.has_value()) << plain.error().message;
  ASSERT_TRUE(ds.has_value()) << ds.error().message;
  EXPECT_EQ(ds->mode, "tc");
  EXPECT_EQ(ds->gnss.rover_obs, plain->gnss.rover_obs);
  EXPECT_EQ(ds->imu.file, plain->imu.file);

  // The scenario's models themselves.
  EXPECT_DOUBLE_EQ(ds->gnss.code_sigma_zenith_m, sim::thermal_code_sigma_m(sc.gnss, sc.gnss.cn0_zenith_dbhz));
  EXPECT_DOUBLE_EQ(ds->gnss.cn0_ref_dbhz, sc.gnss.cn0_zenith_dbhz);
  EXPECT_DOUBLE_EQ(ds->gnss.elevation_weight, 0.0);
  EXPECT_DOUBLE_EQ(ds->antenna.lever_arm_ned_m.z(), -(sc.gnss.antenna_height_m - sc.gait.imu_height_m));
  EXPECT_DOUBLE_EQ(ds->antenna.lever_arm_heading_m.y(), -0.12);
  EXPECT_NEAR(ds->imu.spec.gyro_g_sensitivity, sc.imu.gyro_g_sensitivity_sigma, 1e-15);
  EXPECT_TRUE(ds->multipath.states);
  EXPECT_DOUBLE_EQ(ds->multipath.sigma_m, 0.37);
  EXPECT_DOUBLE_EQ(ds->multipath.tau_s, 12.5);
  EXPECT_DOUBLE_EQ(ds->multipath.cn0_ref_dbhz, 43.0);

  // The same filter as pednav montecarlo's flags (apply_data_sheet on config.yaml) — every other key as config.yaml.
  io::RunConfig want = *plain;
  want.mode = "tc";
  pipeline::apply_data_sheet(sc, pipeline::DataSheetParts::all(), want);
  const fusion::EngineOptions a = pipeline::engine_options(*ds), b = pipeline::engine_options(want);
  EXPECT_DOUBLE_EQ(a.weights.code_sigma_zenith_m, b.weights.code_sigma_zenith_m);
  EXPECT_DOUBLE_EQ(a.weights.doppler_sigma_zenith_mps, b.weights.doppler_sigma_zenith_mps);
  EXPECT_DOUBLE_EQ(a.weights.cn0_ref_dbhz, b.weights.cn0_ref_dbhz);
  EXPECT_DOUBLE_EQ(a.weights.elevation_weight, b.weights.elevation_weight);
  EXPECT_DOUBLE_EQ(a.weights.code_squaring_loss, b.weights.code_squaring_loss);
  EXPECT_EQ(a.lever_arm_n_m, b.lever_arm_n_m);
  EXPECT_EQ(a.lever_arm_heading_m, b.lever_arm_heading_m);
  EXPECT_DOUBLE_EQ(a.multipath_sigma_m, b.multipath_sigma_m);
  EXPECT_DOUBLE_EQ(a.multipath_tau_s, b.multipath_tau_s);
  EXPECT_DOUBLE_EQ(a.multipath_cn0_ref_dbhz, b.multipath_cn0_ref_dbhz);
  EXPECT_NEAR(ds->imu.spec.gyro_g_sensitivity, want.imu.spec.gyro_g_sensitivity, 1e-15);
  // The rest of the spec is the scenario's (the inline spec's unit conversion rounds at the last bit).
  EXPECT_NEAR(ds->imu.spec.gyro_arw, sc.imu.spec.gyro_arw, 1e-12 * sc.imu.spec.gyro_arw);
  EXPECT_NEAR(ds->imu.spec.accel_bias_initial, sc.imu.spec.accel_bias_initial, 1e-12 * sc.imu.spec.accel_bias_initial);

  // A simulated multipath below the configuration's 1 mm minimum: no multipath states (the file still loads).
  f.scenario.gnss.multipath_sigma_m = 1e-4;
  const std::string d2 = test::temp_dir("sim_ds2");
  ASSERT_TRUE(pipeline::run_simulate_command(f, d2).has_value());
  auto ds2 = io::load_run_config(d2 + "/config_datasheet.yaml");
  ASSERT_TRUE(ds2.has_value()) << ds2.error().message;
  EXPECT_FALSE(ds2->multipath.states);
  EXPECT_DOUBLE_EQ(ds2->gnss.carrier_sigma_zenith_m, plain->gnss.carrier_sigma_zenith_m) << "no phase: the default";

  // With carrier phase: the phase σ of the simulated receiver (multipath and PLL noise at the zenith C/N0), read back
  // to the same double, and the same as pednav montecarlo --carrier --receiver-weights gives the filter.
  f.scenario.gnss.carrier_phase = true;
  f.scenario.gnss.carrier_multipath_sigma_m = 0.0071;
  const std::string d3 = test::temp_dir("sim_ds3");
  ASSERT_TRUE(pipeline::run_simulate_command(f, d3).has_value());
  auto ds3 = io::load_run_config(d3 + "/config_datasheet.yaml");
  ASSERT_TRUE(ds3.has_value()) << ds3.error().message;
  const double want_phase = sim::receiver_carrier_sigma_zenith_m(f.scenario.gnss);
  EXPECT_DOUBLE_EQ(ds3->gnss.carrier_sigma_zenith_m, want_phase);
  EXPECT_GT(want_phase, 0.0071) << "multipath and PLL noise in quadrature";
  EXPECT_LT(want_phase, 0.0071 * 1.05) << "PLL noise at 49 dB-Hz: well under the multipath";
  io::RunConfig want3 = *io::load_run_config(d3 + "/config.yaml");
  pipeline::apply_data_sheet(f.scenario, pipeline::DataSheetParts::all(), want3);
  EXPECT_DOUBLE_EQ(pipeline::engine_options(*ds3).carrier_sigma_zenith_m, pipeline::engine_options(want3).carrier_sigma_zenith_m);
}

TEST(SimulateCommand, BadScenarioNamesTheKey) {
  auto f = io::parse_scenario("seed: 1\nstart: {gps_week: 2300, gps_tow_s: 0.5}\norigin: {lat_deg: 1, lon_deg: 2}\n"
                              "route: {waypoints: [{e_m: 0, n_m: 0}, {e_m: 5, n_m: 0}]}\n"
                              "gait: {cycle_s: 9}\nimu: {spec: nope}\n",
                              "bad.yaml", ".");
  ASSERT_FALSE(f.has_value());
  const std::string& m = f.error().message;
  EXPECT_NE(m.find("start.gps_tow_s: must be a whole second"), std::string::npos) << m;
  EXPECT_NE(m.find("gait.cycle_s"), std::string::npos) << m;
  EXPECT_NE(m.find("unknown IMU spec preset 'nope'"), std::string::npos) << m;
}

}  // namespace
}  // namespace pednav
