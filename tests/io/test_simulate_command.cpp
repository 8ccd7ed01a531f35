// `pednav simulate` outputs (io/simulate_command.*): same seed -> byte-identical files; a different seed
// changes them; config.yaml loads as a run configuration pointing at the written files.
#include <gtest/gtest.h>

#include <filesystem>

#include "io/config.hpp"
#include "io/simulate_command.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav {
namespace {

const char* kFiles[] = {"truth.csv", "imu.csv", "rover.obs", "base.obs", "nav.rnx", "blunders.csv", "config.yaml"};

io::ScenarioFile short_walk(uint64_t seed) {
  auto f = test::scenario_from_text(test::kOpenSkyGnssYaml);
  f.scenario.seed = seed;
  f.scenario.waypoints.resize(3);  // one lap's first two legs
  f.scenario.gnss.blunder_rate = 0.01;
  return f;
}

TEST(SimulateCommand, SameSeedGivesByteIdenticalFiles) {
  const std::string a = test::temp_dir("sim_a"), b = test::temp_dir("sim_b"), c = test::temp_dir("sim_c");
  ASSERT_TRUE(io::run_simulate_command(short_walk(7), a).has_value());
  ASSERT_TRUE(io::run_simulate_command(short_walk(7), b).has_value());
  ASSERT_TRUE(io::run_simulate_command(short_walk(8), c).has_value());
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
  ASSERT_TRUE(io::run_simulate_command(short_walk(3), d).has_value());
  auto cfg = io::load_run_config(d + "/config.yaml");
  ASSERT_TRUE(cfg.has_value()) << (cfg ? "" : cfg.error().message);
  EXPECT_EQ(cfg->mode, "gnss");
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
