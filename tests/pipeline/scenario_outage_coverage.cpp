// SPDX-License-Identifier: BSD-2-Clause
// `pednav outage` against a reference with gaps (issue 49 item 8): `--windows K` places each window where the
// reference covers it, and a window the reference cannot score is reported (outages.csv `scored`,
// `unscored_reason`; summary.json `windows_unscored`) while the study goes on. On the simulated open-sky circle
// (datasets/circle_304m.yaml) with its truth cut into a gappy reference.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "eval/outage.hpp"
#include "io/config.hpp"
#include "io/report.hpp"
#include "io/scenario_config.hpp"
#include "pipeline/outage_command.hpp"
#include "pipeline/simulate_command.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav {
namespace {

using ::testing::HasSubstr;
constexpr double kWindowS = 20.0;

class OutageCoverage : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::temp_dir("outage_coverage"));
    auto f = io::load_scenario("datasets/circle_304m.yaml");
    ASSERT_TRUE(f.has_value()) << f.error().message;
    ASSERT_TRUE(pipeline::run_simulate_command(*f, *dir_).has_value());
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  // simulate's config.yaml as written (mode tc: no override needed), scored against `reference` (CSV).
  static io::RunConfig config(const std::string& reference) {
    auto c = io::load_run_config(*dir_ + "/config.yaml");
    EXPECT_TRUE(c.has_value()) << (c ? "" : c.error().message);
    EXPECT_EQ(c->mode, "tc");
    c->reference.file = reference;
    c->reference.format = "csv";
    return *c;
  }
  static pipeline::OutageArgs args(const std::string& name) {
    pipeline::OutageArgs a;
    a.out_dir = *dir_ + "/" + name;
    a.windows = 2;
    a.duration_s = kWindowS;
    a.keep_sats = 0;
    a.converged_sigma_horizontal_m = 3.0;
    a.converged_sigma_yaw_deg = 10.0;
    a.settle_s = 5.0;
    a.plot = false;
    return a;
  }
  // truth.csv without the rows whose time lies in [from, to] (GPS seconds of week): a reference with a gap.
  static std::string reference_with_gap(const std::string& name, double from_tow_s, double to_tow_s) {
    std::istringstream in(test::read_text(*dir_ + "/truth.csv"));
    const std::string path = *dir_ + "/" + name + ".csv";
    std::ofstream out(path);
    std::string line;
    std::getline(in, line);
    out << line << "\n";
    while (std::getline(in, line)) {
      const size_t c1 = line.find(',');
      const double tow = std::stod(line.substr(c1 + 1, line.find(',', c1 + 1) - c1 - 1));
      if (tow < from_tow_s || tow > to_tow_s) out << line << "\n";
    }
    return path;
  }
  static std::string* dir_;
};
std::string* OutageCoverage::dir_ = nullptr;

TEST_F(OutageCoverage, WindowsGoWhereTheReferenceCoversThem) {
  // Where the windows go with the whole truth: its centred slots (the reference covers everything).
  auto full = pipeline::run_outage_command(config(*dir_ + "/truth.csv"), args("full"));
  ASSERT_TRUE(full.has_value()) << full.error().message;
  ASSERT_EQ(full->windows.size(), 2u);
  // Cut the middle of window 1 out of the reference: the window has to move within its slot.
  const eval::OutageWindow w1 = full->windows[0];
  const double gap_from = w1.start.tow_s() + 5.0, gap_to = w1.end().tow_s() - 5.0;
  auto moved = pipeline::run_outage_command(config(reference_with_gap("gap_in_window_1", gap_from, gap_to)),
                                            args("moved"));
  ASSERT_TRUE(moved.has_value()) << moved.error().message;
  ASSERT_EQ(moved->windows.size(), 2u);
  EXPECT_NE(moved->windows[0].start, w1.start) << "the window stayed on the reference's gap";
  const bool clear_of_gap =
      moved->windows[0].end().tow_s() <= gap_from || moved->windows[0].start.tow_s() >= gap_to;
  EXPECT_TRUE(clear_of_gap) << "window 1 at " << moved->windows[0].start.tow_s() << " s overlaps the gap " << gap_from
                            << " .. " << gap_to;
  EXPECT_EQ(moved->windows[1].start, full->windows[1].start) << "window 2 was covered and stays centred";
  EXPECT_LT(moved->windows[0].end(), moved->windows[1].start) << "windows stay apart and in order";
  for (const auto& r : moved->unscored_reason) EXPECT_EQ(r, "");
  std::printf("[outage coverage] window 1 centred at %.0f s, moved to %.0f s (gap %.0f .. %.0f)\n", w1.start.tow_s(),
              moved->windows[0].start.tow_s(), gap_from, gap_to);
}

TEST_F(OutageCoverage, AWindowTheReferenceDoesNotCoverIsReportedAndTheStudyGoesOn) {
  auto full = pipeline::run_outage_command(config(*dir_ + "/truth.csv"), args("full_for_starts"));
  ASSERT_TRUE(full.has_value()) << full.error().message;
  // Explicit windows stay where they are given; the reference misses the second one entirely (and 3 s around it,
  // beyond the 1.5 s the comparison interpolates across).
  pipeline::OutageArgs a = args("unscored");
  for (const auto& w : full->windows) a.start_tow_s.push_back(w.start.tow_s());
  const eval::OutageWindow w2 = full->windows[1];
  const std::string ref = reference_with_gap("gap_over_window_2", w2.start.tow_s() - 3.0, w2.end().tow_s() + 3.0);
  auto r = pipeline::run_outage_command(config(ref), a);
  ASSERT_TRUE(r.has_value()) << "one unscorable window must not discard the study: " << r.error().message;
  ASSERT_EQ(r->unscored_reason.size(), 2u);
  EXPECT_EQ(r->unscored_reason[0], "");
  EXPECT_THAT(r->unscored_reason[1], HasSubstr("the reference has no epoch from"));
  EXPECT_GT(r->forward.per_window[0].samples, 0);
  EXPECT_EQ(r->forward.per_window[1].samples, 0);
  EXPECT_GT(r->forward_vs_run.per_window[1].samples, 0) << "against the run without outage it is still scored";
  // outages.csv: the two new trailing columns.
  const std::string csv = test::read_text(a.out_dir + "/outages.csv");
  EXPECT_THAT(csv.substr(0, csv.find('\n')), ::testing::EndsWith(",end_sigma_smoothed_m,scored,unscored_reason"));
  std::istringstream rows(csv);
  std::string head, row1, row2;
  std::getline(rows, head);
  std::getline(rows, row1);
  std::getline(rows, row2);
  EXPECT_THAT(row1, ::testing::EndsWith(",1,"));
  EXPECT_THAT(row2, HasSubstr(",0,the reference has no epoch from"));
  EXPECT_EQ(std::count(row2.begin(), row2.end(), ','), std::count(head.begin(), head.end(), ','))
      << "the reason must not add cells: " << row2;
  const auto j = nlohmann::json::parse(test::read_text(a.out_dir + "/summary.json"));
  EXPECT_EQ(j["windows"], 2);
  EXPECT_EQ(j["windows_unscored"], 1);
  EXPECT_TRUE(j["window_list"][0]["scored"].get<bool>());
  EXPECT_FALSE(j["window_list"][1]["scored"].get<bool>());
  EXPECT_TRUE(j["window_list"][1]["max_error_m"].is_null());
  EXPECT_THAT(j["window_list"][1]["unscored_reason"].get<std::string>(), HasSubstr("nearest before"));
  // The study's figures are window 1's alone.
  EXPECT_DOUBLE_EQ(r->forward.max_error_m, r->forward.per_window[0].max_m);
  // report.html names the window and why.
  auto report = io::run_report_command(a.out_dir);
  ASSERT_TRUE(report.has_value()) << report.error().message;
  EXPECT_THAT(test::read_text(report->path), HasSubstr(") not scored: the reference has no epoch from"));
}

// The study runs the tc filter on any configuration that has its inputs; one without them is refused by name.
TEST_F(OutageCoverage, OtherModesRunAsTcOrSayWhatIsMissing) {
  io::RunConfig c = config(*dir_ + "/truth.csv");
  c.mode = "gnss";
  pipeline::OutageArgs a = args("from_gnss_mode");
  a.windows = 1;
  auto r = pipeline::run_outage_command(c, a);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  EXPECT_EQ(r->windows.size(), 1u);
  c.mode = "ins";
  c.gnss.rover_obs.clear();
  c.gnss.nav.clear();
  auto bad = pipeline::run_outage_command(c, a);
  ASSERT_FALSE(bad.has_value());
  EXPECT_THAT(bad.error().message, HasSubstr("mode ins: pednav outage runs the tightly coupled filter, which needs "
                                             "rover_obs, nav (missing here)"));
}

}  // namespace
}  // namespace pednav
