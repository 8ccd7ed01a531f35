// SPDX-License-Identifier: BSD-2-Clause
// README's "A first run" cannot drift (issue 49 item 7): its minimal configuration, taken from README.md as printed,
// runs with `pednav run` on the data scripts/demo simulates (datasets/forest_walk.yaml), and the accuracy lines the
// README shows are the ones the run prints (its evaluation.json and evaluation_smoothed.json, to the 2 decimals shown).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "io/scenario_config.hpp"
#include "pipeline/simulate_command.hpp"
#include "tests/sim/fixtures.hpp"
#include "tests/support/data.hpp"

namespace pednav {
namespace {

// The README's text between `begin` and the end of its fenced block.
std::string fenced_block(const std::string& readme, const std::string& begin) {
  const size_t b = readme.find(begin);
  if (b == std::string::npos) return "";
  const size_t e = readme.find("```", b);
  return readme.substr(b, e == std::string::npos ? std::string::npos : e - b);
}

// "<which> vs reference: horizontal RMS X m" in the README's console block: X, or -1.
double readme_rms(const std::string& console, const std::string& which) {
  const std::string lead = which + " vs reference: horizontal RMS ";
  const size_t at = console.find(lead);
  if (at == std::string::npos) return -1.0;
  const size_t b = at + lead.size();
  const size_t e = console.find_first_not_of("0123456789.", b);
  if (e == b || e == std::string::npos || console.compare(e, 2, " m") != 0) return -1.0;
  return std::stod(console.substr(b, e - b));
}

TEST(ReadmeFirstRun, TheMinimalConfigurationRunsAndPrintsWhatTheReadmeShows) {
  const std::string readme = test::read_text(test::source_path("README.md"));
  const std::string yaml = fenced_block(readme, "# out/demo/minimal.yaml\n");
  ASSERT_FALSE(yaml.empty()) << "README.md has no ```yaml block starting with # out/demo/minimal.yaml";
  const std::string console = fenced_block(readme, "$ build/bin/pednav run out/demo/minimal.yaml");
  const double forward_rms_m = readme_rms(console, "forward"), smoothed_rms_m = readme_rms(console, "smoothed");
  ASSERT_GT(forward_rms_m, 0.0) << console;
  ASSERT_GT(smoothed_rms_m, 0.0) << console;

  // scripts/demo's data: out/demo/data.
  const std::string dir = test::temp_dir("readme_first_run");
  auto sc = io::load_scenario(test::source_path("datasets/forest_walk.yaml"));
  ASSERT_TRUE(sc.has_value()) << sc.error().message;
  ASSERT_TRUE(pipeline::run_simulate_command(*sc, dir + "/data").has_value());
  std::ofstream(dir + "/minimal.yaml") << yaml;
  const std::string cmd = std::string(PEDNAV_BINARY_DIR) + "/bin/pednav -q run " + dir + "/minimal.yaml -o " + dir +
                          "/minimal 2> " + dir + "/stderr.txt";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << test::read_text(dir + "/stderr.txt");
  const auto fwd = nlohmann::json::parse(test::read_text(dir + "/minimal/evaluation.json"));
  const auto smo = nlohmann::json::parse(test::read_text(dir + "/minimal/evaluation_smoothed.json"));
  // The README prints 2 decimals: the run's figure rounds to it.
  constexpr double kHalfLastDigit_m = 0.005;
  EXPECT_NEAR(fwd["horizontal_rms_m"].get<double>(), forward_rms_m, kHalfLastDigit_m)
      << "README.md's first run shows another forward RMS than the run gives: update the README";
  EXPECT_NEAR(smo["horizontal_rms_m"].get<double>(), smoothed_rms_m, kHalfLastDigit_m)
      << "README.md's first run shows another smoothed RMS than the run gives: update the README";
}

}  // namespace
}  // namespace pednav
