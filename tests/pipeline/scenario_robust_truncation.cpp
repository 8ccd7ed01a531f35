// SPDX-License-Identifier: BSD-2-Clause
// Truncated input files (issue 11, docs/robustness.md): a simulated rover RINEX 3 file and IMU log cut at many
// offsets, mid-line included. Reading gives a prefix of the full data with the truncation reported (never a cut
// number), or an error naming the file; `pednav run` on cut files completes with the truncation in summary.json or
// fails with a clear message — never a crash, a hang or a NaN.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "gnss/rtklib/rinex.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "pipeline/run_command.hpp"
#include "pipeline/simulate_command.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav {
namespace {

using ::testing::HasSubstr;

constexpr int kReadOffsets = 60;   // cut positions per file for the reader
constexpr int kRunOffsets = 3;     // cut positions per file for a whole `pednav run`
constexpr unsigned kSeed = 11;

const std::string kShortWalkYaml = test::small_rectangle_walk_yaml("robust_truncation", 5, 500000, "{lat_deg: 40.4, lon_deg: -3.7, h_m: 650}", 1);

const std::string& sim_dir() {
  static const std::string d = [] {
    const std::string dir = test::temp_dir("robust_truncation");
    auto r = pipeline::run_simulate_command(test::scenario_from_text(kShortWalkYaml), dir);
    EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
    return dir;
  }();
  return d;
}

// Cut positions: a fixed-seed random sample over the body plus the ends of the last lines (mid-line included).
std::vector<size_t> cut_positions(const std::string& text, size_t body_start, int n) {
  std::mt19937 rng(kSeed);
  std::uniform_int_distribution<size_t> u(body_start, text.size() - 1);
  std::vector<size_t> cuts;
  for (int i = 0; i < n; ++i) cuts.push_back(u(rng));
  for (size_t k = 1; k < 200 && k < text.size(); k += 7) cuts.push_back(text.size() - k);
  return cuts;
}

std::string write_cut(const std::string& name, const std::string& text, size_t cut) {
  const std::string p = sim_dir() + "/" + name;
  std::ofstream(p, std::ios::binary) << text.substr(0, cut);
  return p;
}

TEST(RobustRinexTruncation, CutRoverObsGivesAPrefixWithTruncationReportedOrAClearError) {
  const std::string full_path = sim_dir() + "/rover.obs";
  const std::string text = test::read_text(full_path);
  const gnss::SystemSelection gps;
  auto full = gnss::read_rinex_obs(full_path, gps);
  ASSERT_TRUE(full) << full.error().message;
  ASSERT_FALSE(full->stats.truncated);
  const size_t body = text.find("END OF HEADER");
  ASSERT_NE(body, std::string::npos);
  int ok = 0, failed = 0, dropped = 0;
  for (size_t cut : cut_positions(text, body / 2, kReadOffsets)) {
    const std::string p = write_cut("cut.obs", text, cut);
    auto r = gnss::read_rinex_obs(p, gps);
    if (!r) {
      ++failed;
      EXPECT_THAT(r.error().message, HasSubstr("cut.obs")) << "cut at " << cut;
      continue;
    }
    ++ok;
    const bool mid_line = text[cut - 1] != '\n';
    EXPECT_TRUE(r->stats.truncated || !mid_line) << "cut at " << cut << " not reported";
    dropped += r->stats.last_epoch_dropped;
    ASSERT_LE(r->epochs.size(), full->epochs.size());
    for (size_t i = 0; i < r->epochs.size(); ++i) {  // every epoch read is the full file's epoch, number for number
      const auto& a = r->epochs[i];
      const auto& b = full->epochs[i];
      ASSERT_EQ(a.time, b.time) << "cut at " << cut;
      ASSERT_EQ(a.sats.size(), b.sats.size()) << "cut at " << cut << ", epoch " << a.time.to_string();
      for (size_t k = 0; k < a.sats.size(); ++k) {
        ASSERT_TRUE(a.sats[k].sat == b.sats[k].sat);
        ASSERT_TRUE(a.sats[k].pseudorange_m == b.sats[k].pseudorange_m ||
                    (std::isnan(a.sats[k].pseudorange_m) && std::isnan(b.sats[k].pseudorange_m)))
            << "cut at " << cut << ": a cut pseudorange was kept (" << a.sats[k].pseudorange_m << " vs "
            << b.sats[k].pseudorange_m << ")";
        ASSERT_TRUE(a.sats[k].doppler_hz == b.sats[k].doppler_hz ||
                    (std::isnan(a.sats[k].doppler_hz) && std::isnan(b.sats[k].doppler_hz)))
            << "cut at " << cut << ": a cut Doppler was kept";
      }
    }
  }
  // Measured 2026-12-05 over the 89 cuts (60 random + 29 at the file's end): 86 read, 13 of them with the cut last
  // epoch dropped, 3 clear errors (cuts inside the header's continuation). The cuts and the file are deterministic
  // (fixed seed, simulated file); the bounds allow a few cuts to move between the outcomes (another standard
  // library's uniform_int_distribution gives other cut positions): read ≥ 90 % of measured, dropped within ±30 %.
  EXPECT_GE(ok, 86 * 9 / 10);
  EXPECT_NEAR(dropped, 13, 4);  // some cuts end inside the last satellite line of a record
  EXPECT_LE(failed, 3 + 6);
  std::printf("[ robust ] rover.obs cut at %d offsets: %d read (%d with the cut last epoch dropped), %d errors\n",
              ok + failed, ok, dropped, failed);
}

TEST(RobustImuTruncation, CutSimulatedImuLogGivesAPrefixOrAClearError) {
  const std::string full_path = sim_dir() + "/imu.csv";
  const std::string text = test::read_text(full_path);
  auto cfg = io::load_run_config(sim_dir() + "/config.yaml");
  ASSERT_TRUE(cfg) << cfg.error().message;
  auto full = io::read_imu_csv(full_path, cfg->imu.format);
  ASSERT_TRUE(full) << full.error().message;
  int ok = 0, failed = 0;
  for (size_t cut : cut_positions(text, 0, kReadOffsets)) {
    auto r = io::read_imu_csv(write_cut("cut_imu.csv", text, cut), cfg->imu.format);
    if (!r) {
      ++failed;
      EXPECT_THAT(r.error().message, HasSubstr("cut_imu.csv")) << "cut at " << cut;
      continue;
    }
    ++ok;
    ASSERT_LE(r->samples.size(), full->samples.size());
    for (size_t i = 0; i < r->samples.size(); ++i) {
      ASSERT_EQ(r->samples[i].t, full->samples[i].t);
      ASSERT_EQ(r->samples[i].omega_ib_b, full->samples[i].omega_ib_b) << "cut at " << cut;
      ASSERT_EQ(r->samples[i].f_ib_b, full->samples[i].f_ib_b) << "cut at " << cut;
    }
    EXPECT_EQ(r->report.truncated_rows, text[cut - 1] != '\n' ? 1 : 0) << "cut at " << cut;
  }
  std::printf("[ robust ] imu.csv cut at %d offsets: %d read, %d errors\n", ok + failed, ok, failed);
  EXPECT_GT(ok, kReadOffsets / 2);
  // Measured 2026-12-05: all 89 cuts read (a cut IMU log is a prefix); two may move to a clear error (cuts that
  // leave too few samples, another standard library's cut positions).
  EXPECT_GE(ok, 89 - 2);
}

// Whole runs on cut files: completes (truncation in summary.json, finite solution) or fails naming the file.
TEST(RobustRunTruncation, RunOnCutFilesCompletesWithTruncationReportedOrFailsClearly) {
  auto cfg0 = io::load_run_config(sim_dir() + "/config.yaml");
  ASSERT_TRUE(cfg0) << cfg0.error().message;
  const std::string obs = test::read_text(sim_dir() + "/rover.obs");
  const std::string imu = test::read_text(sim_dir() + "/imu.csv");
  // Cuts in the last quarter (a run needs the walk's start), mid-line.
  std::vector<std::pair<std::string, size_t>> cuts;
  for (int k = 1; k <= kRunOffsets; ++k) {
    cuts.push_back({"obs", obs.size() - obs.size() * k / 13 - 17});
    cuts.push_back({"imu", imu.size() - imu.size() * k / 13 - 5});
  }
  int completed = 0;
  for (const auto& [what, cut] : cuts) {
    io::RunConfig c = *cfg0;
    c.mode = "tc";
    c.smoother_enabled = false;
    c.reference.file.clear();
    if (what == "obs") c.gnss.rover_obs = write_cut("run_cut.obs", obs, cut);
    else c.imu.file = write_cut("run_cut_imu.csv", imu, cut);
    const std::string out = sim_dir() + "/out_" + what;
    std::filesystem::remove_all(out);
    auto r = pipeline::run_run_command(c, out);
    if (!r) {
      EXPECT_THAT(r.error().message, HasSubstr(what == "obs" ? "run_cut.obs" : "run_cut_imu.csv"));
      continue;
    }
    ++completed;
    const auto j = nlohmann::json::parse(test::read_text(out + "/summary.json"));
    if (what == "obs") {
      EXPECT_TRUE(j["accounting"]["rover_obs"]["truncated"].get<bool>()) << "cut at " << cut;
    } else {
      EXPECT_EQ(j["accounting"]["imu_samples"]["skipped"]["truncated_last_row"].get<long>(), 1) << "cut at " << cut;
    }
    const std::string sol = test::read_text(out + "/solution.csv");
    EXPECT_EQ(sol.find("nan"), std::string::npos) << what << " cut at " << cut;
    EXPECT_EQ(sol.find("inf"), std::string::npos) << what << " cut at " << cut;
  }
  EXPECT_EQ(completed, static_cast<int>(cuts.size()));  // cuts late in the files leave enough data to run
}

long sum_of(const nlohmann::json& m) {
  long n = 0;
  for (const auto& [k, v] : m.items()) n += v.get<long>();
  return n;
}

// summary.json accounting on a log with NaN rows and a duplicate burst: read = used + rejected + skipped.
TEST(RobustAccounting, SummaryJsonIdentityHolds) {
  auto c = io::load_run_config(sim_dir() + "/config.yaml");
  ASSERT_TRUE(c) << c.error().message;
  std::string imu = test::read_text(sim_dir() + "/imu.csv");
  const size_t at = imu.find('\n', imu.size() / 2) + 1;
  const std::string row = imu.substr(at, imu.find('\n', at) - at + 1);
  imu.insert(at, row + row + row);                              // 3 duplicates
  std::string nan_row = row;
  nan_row.replace(nan_row.rfind(','), std::string::npos, ",nan\n");
  imu.insert(imu.find('\n', at + 4 * row.size()) + 1, nan_row);  // 1 NaN row (same time: a bad row first)
  c->mode = "tc";
  c->imu.file = write_cut("acc_imu.csv", imu, imu.size());
  const std::string out = sim_dir() + "/out_accounting";
  auto r = pipeline::run_run_command(*c, out);
  ASSERT_TRUE(r) << r.error().message;
  const auto j = nlohmann::json::parse(test::read_text(out + "/summary.json"));
  const auto& a = j["accounting"];
  const auto& i = a["imu_samples"];
  EXPECT_EQ(i["read"].get<long>(), i["used"].get<long>() + sum_of(i["rejected"]) + sum_of(i["skipped"])) << a.dump(1);
  EXPECT_EQ(i["rejected"]["duplicate_time"].get<long>(), 3);
  EXPECT_EQ(i["rejected"]["unparsable_or_non_finite_row"].get<long>(), 1);
  const auto& g = a["gnss_measurements"];
  EXPECT_EQ(g["read"].get<long>(), g["used"].get<long>() + sum_of(g["rejected"]) + sum_of(g["skipped"])) << a.dump(1);
  EXPECT_GT(g["used"].get<long>(), 0);
  EXPECT_TRUE(j["health"]["healthy"].get<bool>());
}

}  // namespace
}  // namespace pednav
