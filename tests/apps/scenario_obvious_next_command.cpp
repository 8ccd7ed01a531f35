// SPDX-License-Identifier: BSD-2-Clause
// The obvious next command works (issue 49 item 8), through the executable as a newcomer types it: `pednav simulate`
// writes a config.yaml (mode tc) that `pednav run`, `pednav gnss` and `pednav outage --full` take without `--mode`;
// `pednav run` runs a file written for `pednav gnss` (mode gnss) as tc when it has the IMU log, and says what is
// missing when it has none. On datasets/circle_304m.yaml (243 s, open sky).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/sim/fixtures.hpp"
#include "tests/support/data.hpp"

namespace pednav {
namespace {

using ::testing::HasSubstr;

// Exit status of `pednav ARGS`, with its stderr in *err.
int pednav(const std::string& args, const std::string& err_file, std::string* err = nullptr) {
  const std::string cmd = std::string(PEDNAV_BINARY_DIR) + "/bin/pednav -q " + args + " > /dev/null 2> " + err_file;
  const int status = std::system(cmd.c_str());
  if (err) *err = test::read_text(err_file);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string summary_mode(const std::string& dir) {
  return nlohmann::json::parse(test::read_text(dir + "/summary.json")).value("mode", std::string());
}

TEST(ObviousNextCommand, SimulateThenRunGnssAndOutageOnTheWrittenConfig) {
  const std::string dir = test::temp_dir("next_command");
  const std::string err = dir + "/stderr.txt";
  std::string msg;
  ASSERT_EQ(pednav("simulate " + test::source_path("datasets/circle_304m.yaml") + " -o " + dir + "/data", err, &msg),
            0) << msg;
  const std::string config = test::read_text(dir + "/data/config.yaml");
  EXPECT_THAT(config, HasSubstr("\nmode: tc\n"));

  ASSERT_EQ(pednav("run " + dir + "/data/config.yaml -o " + dir + "/run", err, &msg), 0) << msg;
  EXPECT_EQ(summary_mode(dir + "/run"), "tc");
  for (const char* f : {"solution.csv", "smoothed.csv", "residuals.csv", "evaluation.json"}) {
    EXPECT_TRUE(std::filesystem::exists(dir + "/run/" + f)) << f;
  }
  ASSERT_EQ(pednav("gnss " + dir + "/data/config.yaml -o " + dir + "/gnss", err, &msg), 0) << msg;
  EXPECT_TRUE(std::filesystem::exists(dir + "/gnss/gnss.csv"));
  ASSERT_EQ(pednav("outage " + dir + "/data/config.yaml --full --windows 1 --duration 20 --converged-sigma-m 3 "
                   "--converged-yaw-deg 10 --settle 5 --no-plot -o " + dir + "/outage",
                   err, &msg),
            0) << msg;
  EXPECT_TRUE(std::filesystem::exists(dir + "/outage/outages.csv"));

  // The same file with mode gnss (what simulate wrote before): run runs tc on it and says so.
  std::string as_gnss = config;
  as_gnss.replace(as_gnss.find("\nmode: tc\n"), 10, "\nmode: gnss\n");
  std::ofstream(dir + "/data/config_gnss.yaml") << as_gnss;
  ASSERT_EQ(pednav("run " + dir + "/data/config_gnss.yaml -o " + dir + "/run_gnss", err, &msg), 0) << msg;
  EXPECT_EQ(summary_mode(dir + "/run_gnss"), "tc");
  EXPECT_EQ(test::read_text(dir + "/run_gnss/solution.csv"), test::read_text(dir + "/run/solution.csv"))
      << "mode gnss runs exactly the tc filter";

  // A GNSS-only file: run names what it lacks and where the GNSS-only solution is.
  std::ofstream(dir + "/data/gnss_only.yaml")
      << "mode: gnss\nrover_obs: rover.obs\nbase_obs: base.obs\nnav: [nav.rnx]\n";
  EXPECT_EQ(pednav("run " + dir + "/data/gnss_only.yaml -o " + dir + "/run_bad", err, &msg), 1);
  EXPECT_THAT(msg, HasSubstr("gnss_only.yaml: mode gnss: pednav run runs the tightly coupled filter, which needs "
                             "imu.file (missing here); `pednav gnss` gives the GNSS-only solution"));
  EXPECT_EQ(std::count(msg.begin(), msg.end(), '\n'), 1) << "one line: " << msg;
}

}  // namespace
}  // namespace pednav
