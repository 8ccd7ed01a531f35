// SPDX-License-Identifier: BSD-2-Clause
// Issue 49 item 4: the smoothed solution against the forward one on every committed scenario with a reference
// (datasets/*.yaml; galway_track needs the shared data and is checked in tests/sim/data_galway_track.cpp). Each
// scenario is simulated and run as a user would (`pednav simulate`, then `pednav run` of the written config.yaml; the
// unknown sensors with the minimal configuration, the carrier walk also with `gnss.carrier: on`) and both solutions
// are compared with the truth: start as configured, and for the INS-only loops also after a best-fit 2-D alignment
// (their heading is unobservable). Where the smoothed RMS is above the forward one the row says why
// (docs/results.md "Smoothed against forward"); everywhere else smoothed <= forward is required.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "io/config.hpp"
#include "io/scenario_config.hpp"
#include "pipeline/compare_command.hpp"
#include "pipeline/run_command.hpp"
#include "pipeline/simulate_command.hpp"
#include "tests/support/data.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav {
namespace {

enum class Setup { kWritten, kMinimal, kCarrierOn };

struct Case {
  const char* scenario;  // datasets/<scenario>.yaml
  Setup setup;
  eval::Align align;
  double forward_m;   // horizontal RMS, measured 2026-12-06 (Release, deterministic)
  double smoothed_m;
  const char* exception;  // nullptr: smoothed <= forward is required; else why it is above (docs/results.md)
};

// Bounds: each figure within 2 % of its measured value (the runs are deterministic; the margin is for another libm),
// and the ordering. An exception that stops holding fails too: take it out of the list and out of docs/results.md.
constexpr double kFigureTolerance = 0.02;

constexpr const char* kHeadingDraw =
    "INS-only loop: the heading random walk neither pass observes dominates, and on single draws the smoother is "
    "worse on about a third even when the model fits (docs/results.md)";
constexpr const char* kCarrierDraw =
    "seed 2 of the carrier walk: the smoother is worse in its last 12 min of float phase (seeds 3-8: better on all)";

const Case kCases[] = {
    {"circle_304m", Setup::kWritten, eval::Align::kNone, 0.6143, 0.3885, nullptr},
    {"square_75m", Setup::kWritten, eval::Align::kNone, 0.7174, 0.5286, nullptr},
    {"forest_walk", Setup::kWritten, eval::Align::kNone, 1.0768, 0.4506, nullptr},
    {"forest_walk_carrier", Setup::kWritten, eval::Align::kNone, 1.0768, 0.4506, nullptr},  // carrier auto: code only
    {"forest_walk_carrier", Setup::kCarrierOn, eval::Align::kNone, 0.3643, 0.4158, kCarrierDraw},
    {"forest_walk_hand", Setup::kWritten, eval::Align::kNone, 1.6680, 0.9784, nullptr},
    {"indoor_loops", Setup::kWritten, eval::Align::kNone, 0.6261, 0.5992, nullptr},
    {"indoor_loops", Setup::kWritten, eval::Align::kBestFit2d, 0.2065, 0.1429, nullptr},
    {"long_route", Setup::kWritten, eval::Align::kNone, 76.7406, 75.3567, nullptr},
    {"long_route", Setup::kWritten, eval::Align::kBestFit2d, 42.5515, 42.5452, nullptr},
    {"unknown_sensor", Setup::kMinimal, eval::Align::kNone, 0.4022, 0.6237, kHeadingDraw},
    {"unknown_sensor", Setup::kMinimal, eval::Align::kBestFit2d, 0.2711, 0.4956, kHeadingDraw},
    {"unknown_sensor_60hz", Setup::kMinimal, eval::Align::kNone, 1.3129, 1.4553, kHeadingDraw},
    {"unknown_sensor_60hz", Setup::kMinimal, eval::Align::kBestFit2d, 0.3461, 0.3210, nullptr},
    // The configured start yaw is the foot's, the sensor is turned 90° on it: only the best fit scores the shape.
    {"unknown_sensor_1000hz", Setup::kMinimal, eval::Align::kNone, 25.2416, 24.4247, nullptr},
    {"unknown_sensor_1000hz", Setup::kMinimal, eval::Align::kBestFit2d, 1.7840, 1.5800, nullptr},
};

const char* setup_name(Setup s) {
  switch (s) {
    case Setup::kWritten: return "written";
    case Setup::kMinimal: return "minimal";
    case Setup::kCarrierOn: return "carrier on";
  }
  return "?";
}

const char* align_name(eval::Align a) { return a == eval::Align::kNone ? "start as configured" : "best-fit 2-D"; }

// Simulates the scenario once per (scenario, setup) and runs it; the folder holds truth.csv and run/.
std::string simulate_and_run(const Case& c) {
  const std::string name = std::string(c.scenario) + "_" + std::to_string(static_cast<int>(c.setup));
  const std::filesystem::path dir = test::temp_dir_path("smoothed_vs_forward_" + name);
  if (std::filesystem::exists(dir / "run" / "smoothed.csv")) return dir.string();
  std::filesystem::remove_all(dir);
  auto file = io::load_scenario(test::source_path("datasets/" + std::string(c.scenario) + ".yaml"));
  EXPECT_TRUE(file) << (file ? "" : file.error().message);
  if (!file) return "";
  auto sim = pipeline::run_simulate_command(*file, dir.string());
  EXPECT_TRUE(sim) << (sim ? "" : sim.error().message);
  std::string config = (dir / "config.yaml").string();
  if (c.setup == Setup::kMinimal) {  // the written configuration without its `spec:` line
    std::ifstream in(config);
    config = (dir / "minimal.yaml").string();
    std::ofstream minimal(config);
    for (std::string line; std::getline(in, line);) {
      if (line.find("  spec:") != 0) minimal << line << "\n";
    }
  }
  auto cfg = io::load_run_config(config);
  EXPECT_TRUE(cfg) << (cfg ? "" : cfg.error().message);
  if (!cfg) return "";
  if (c.setup == Setup::kCarrierOn) cfg->gnss.carrier = "on";
  EXPECT_TRUE(cfg->smoother_enabled) << c.scenario << ": the written configuration runs the smoother";
  auto sum = pipeline::run_run_command(*cfg, (dir / "run").string());
  EXPECT_TRUE(sum) << (sum ? "" : sum.error().message);
  return dir.string();
}

double rms(const std::string& dir, const char* which, eval::Align align, const std::string& out) {
  pipeline::CompareArgs args;
  args.solution = dir + "/run/" + which + ".csv";
  args.reference = dir + "/truth.csv";
  args.out_dir = out;
  args.compare.align = align;
  args.plots = false;
  auto ev = pipeline::run_compare(args);
  EXPECT_TRUE(ev) << (ev ? "" : ev.error().message);
  return ev ? ev->horizontal_rms_m : -1.0;
}

TEST(SmoothedVsForward, EveryScenarioWithAReference) {
  int required = 0, exceptions = 0;
  for (const Case& c : kCases) {
    const std::string dir = simulate_and_run(c);
    ASSERT_FALSE(dir.empty()) << c.scenario;
    const std::string tag = std::string(c.scenario) + " (" + setup_name(c.setup) + ", " + align_name(c.align) + ")";
    const std::string cmp = dir + "/cmp_" + std::to_string(static_cast<int>(c.align));
    const double f = rms(dir, "solution", c.align, cmp + "_forward");
    const double s = rms(dir, "smoothed", c.align, cmp + "_smoothed");
    std::printf("[smoothed vs forward] %-62s forward %8.4f m, smoothed %8.4f m%s\n", tag.c_str(), f, s,
                c.exception ? "  (exception)" : "");
    EXPECT_NEAR(f, c.forward_m, kFigureTolerance * c.forward_m) << tag;
    EXPECT_NEAR(s, c.smoothed_m, kFigureTolerance * c.smoothed_m) << tag;
    if (c.exception) {
      ++exceptions;
      EXPECT_GT(s, f) << tag << ": no longer an exception (" << c.exception << ")";
    } else {
      ++required;
      EXPECT_LE(s, f) << tag << ": the smoothed solution is worse than the forward one";
    }
  }
  std::printf("[smoothed vs forward] %d rows required smoothed <= forward, %d listed exceptions\n", required,
              exceptions);
  EXPECT_EQ(required, 12);
  EXPECT_EQ(exceptions, 4);
}

// Every committed scenario with a reference is in the list above (galway_track: tests/sim/data_galway_track.cpp).
TEST(SmoothedVsForward, TheListHasEveryCommittedScenario) {
  std::set<std::string> listed = {"galway_track"};
  for (const Case& c : kCases) listed.insert(c.scenario);
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(test::source_path("datasets"))) {
    if (e.path().extension() != ".yaml") continue;
    ++files;
    EXPECT_TRUE(listed.count(e.path().stem().string())) << e.path().filename() << " is not in kCases";
  }
  EXPECT_EQ(files, 11);
}

}  // namespace
}  // namespace pednav
