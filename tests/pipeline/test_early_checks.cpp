// SPDX-License-Identifier: BSD-2-Clause
// Every input path is checked before any processing (issue 36): a run whose reference file does not exist fails at
// once naming the key and the path, and writes no output folder.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav::pipeline {
namespace {

using ::testing::HasSubstr;

TEST(EarlyChecks, AMissingReferenceFailsBeforeProcessingNamingKeyAndPath) {
  const std::string dir = test::temp_dir("early_checks");
  { std::ofstream(dir + "/imu.csv") << "t,gx,gy,gz,ax,ay,az\n"; }
  const std::string yaml = "mode: ins\nimu:\n  file: imu.csv\n  format: pyshoe\n  spec: gx5_25\n"
                           "initial: {lat_deg: 45, lon_deg: 0, h_m: 0, yaw_deg: 0}\n"
                           "reference:\n  file: nowhere/ref.csv\n  format: csv\n";
  { std::ofstream(dir + "/cfg.yaml") << yaml; }
  auto cfg = io::load_run_config(dir + "/cfg.yaml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  const auto missing = io::missing_input_files(*cfg);
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_THAT(missing.front(), HasSubstr("reference.file: " + dir + "/nowhere/ref.csv does not exist"));
  auto r = run_run_command(*cfg, dir + "/out");
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("reference.file: "));
  EXPECT_FALSE(std::filesystem::exists(dir + "/out"));
  std::filesystem::remove(dir + "/imu.csv");
  EXPECT_EQ(io::missing_input_files(*cfg).size(), 2u);  // the IMU log too, all at once
}

// `pednav config-check` and `pednav run` accept the same configurations (issue 49 item 6): what the engine options
// or the IMU format reject at run time is in run_config_problems, which config-check prints and run refuses with.
TEST(EarlyChecks, ConfigCheckAndRunRejectTheSameValues) {
  const std::string dir = test::temp_dir("early_checks_agree");
  { std::ofstream(dir + "/imu.csv") << "t,gx,gy,gz,ax,ay,az\n"; }
  const std::string base = "mode: ins\nimu:\n  file: imu.csv\n  format: pyshoe\n  spec: gx5_25\n";
  const std::string start = "initial: {lat_deg: 45, lon_deg: 0, h_m: 0, yaw_deg: 0}\n";
  struct Case {
    std::string yaml;
    const char* problem;
  };
  // Each passes the YAML reader and was rejected only when the run started (engine options; the IMU log's columns).
  const Case cases[] = {
      {start + "fault_rejection: {probability: 0.5}\n", "fault_rejection.probability must be in (0.5, 1)"},
      {"initial: {lat_deg: 45, lon_deg: 0, h_m: 0, heading: magnetometer}\n",
       "initial.heading: magnetometer needs the magnetometer columns of imu.format"},
  };
  for (const Case& c : cases) {
    auto cfg = io::parse_run_config(base + c.yaml, dir + "/cfg.yaml", dir);
    ASSERT_TRUE(cfg) << c.yaml << cfg.error().message;
    const auto problems = run_config_problems(*cfg);
    ASSERT_EQ(problems.size(), 1u) << c.yaml;
    EXPECT_THAT(problems.front(), HasSubstr(c.problem));
    auto r = run_run_command(*cfg, dir + "/out");
    ASSERT_FALSE(r) << c.yaml;
    EXPECT_THAT(r.error().message, HasSubstr(c.problem));
    EXPECT_FALSE(std::filesystem::exists(dir + "/out"));
  }
  auto ok = io::parse_run_config(base + start, dir + "/cfg.yaml", dir);
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_TRUE(run_config_problems(*ok).empty());
  // A run needs the IMU format; without a spec the log calibrates itself and, with the SHOE detector and no
  // threshold, takes its own threshold (the default); a given threshold or spec wins. A GNSS-only configuration needs
  // neither.
  auto no_spec = io::parse_run_config("mode: ins\nimu: {file: imu.csv, format: pyshoe}\n", dir + "/cfg.yaml", dir);
  ASSERT_TRUE(no_spec) << no_spec.error().message;
  EXPECT_TRUE(run_config_problems(*no_spec).empty());
  EXPECT_TRUE(no_spec->imu.spec_auto && no_spec->imu.spec_defaulted && !no_spec->imu.has_spec);
  EXPECT_TRUE(no_spec->zupt.shoe_threshold_auto && no_spec->zupt.shoe_threshold_defaulted);
  auto given = io::parse_run_config("mode: ins\nimu: {file: imu.csv, format: pyshoe}\nzupt: {shoe_threshold: 3e5}\n",
                                    dir + "/cfg.yaml", dir);
  ASSERT_TRUE(given) << given.error().message;
  EXPECT_TRUE(given->imu.spec_auto);
  EXPECT_FALSE(given->zupt.shoe_threshold_auto);
  EXPECT_EQ(given->zupt.shoe_threshold, 3e5);
  auto preset = io::parse_run_config("mode: ins\nimu: {file: imu.csv, format: pyshoe, spec: gx5_25}\n",
                                     dir + "/cfg.yaml", dir);
  ASSERT_TRUE(preset) << preset.error().message;
  EXPECT_FALSE(preset->imu.spec_auto);
  EXPECT_FALSE(preset->zupt.shoe_threshold_auto);
  auto mv = io::parse_run_config("mode: ins\nimu: {file: imu.csv, format: pyshoe}\nzupt: {detector: mv}\n",
                                 dir + "/cfg.yaml", dir);
  ASSERT_TRUE(mv) << mv.error().message;
  EXPECT_FALSE(mv->zupt.shoe_threshold_auto);  // the threshold is the SHOE detector's
  auto gnss = io::parse_run_config("mode: gnss\nrover_obs: r.obs\nnav: n.nav\n", dir + "/cfg.yaml", dir);
  ASSERT_TRUE(gnss) << gnss.error().message;
  EXPECT_TRUE(run_config_problems(*gnss).empty());
}

}  // namespace
}  // namespace pednav::pipeline
