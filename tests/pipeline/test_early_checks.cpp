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

}  // namespace
}  // namespace pednav::pipeline
