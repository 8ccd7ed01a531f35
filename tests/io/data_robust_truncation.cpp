// SPDX-License-Identifier: BSD-2-Clause
// Truncation of real files (issue 11, docs/robustness.md): RINEX 3.04 (Septentrio rover), RINEX 2.11 (GLW1 CORS) and
// an x-io NGIMU log cut at many offsets within their first few hundred kB (mid-line included). Reading gives exactly
// a prefix of the uncut data (no cut number kept) with the truncation reported, or an error naming the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "gnss/rtklib/rinex.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "tests/support/data.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav {
namespace {

using ::testing::HasSubstr;
using test::shared_data;

constexpr size_t kPrefixBytes = 300000;  // cut within the first 300 kB (keeps each read short)
constexpr int kCuts = 25;
constexpr size_t kNearLineEndBytes = 40;
constexpr unsigned kSeed = 17;

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// kCuts positions uniform over [from, kPrefixBytes), and kCuts more in the last 40 bytes of a random line (inside
// the numbers near a line end: where RTKLIB would decode a cut last satellite line).
std::vector<size_t> cuts_in(const std::string& text, size_t from) {
  std::mt19937 rng(kSeed);
  std::uniform_int_distribution<size_t> u(from, std::min(text.size(), kPrefixBytes) - 1);
  std::uniform_int_distribution<size_t> back(1, kNearLineEndBytes);
  std::vector<size_t> c;
  for (int i = 0; i < kCuts; ++i) c.push_back(u(rng));
  for (int i = 0; i < kCuts; ++i) {
    const size_t nl = text.find('\n', u(rng));
    const size_t line_start = text.rfind('\n', nl - 1) + 1;
    const size_t cut = nl - std::min(back(rng), nl - line_start - 1);
    if (cut > from) c.push_back(cut);
  }
  return c;
}

// This process's temporary folder, made once.
const std::string& kTempDir() {
  static const std::string dir = test::temp_dir("robust_data");
  return dir;
}

std::string write_cut(const std::string& name, const std::string& text, size_t cut) {
  const std::string p = (std::filesystem::path(kTempDir()) / name).string();
  std::ofstream(p, std::ios::binary) << text.substr(0, cut);
  return p;
}

bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

// Outcome counts of the cuts, measured on 2026-12-05: the cuts are fixed (seed 17, libstdc++'s
// uniform_int_distribution) and the files too, so the counts are exact for this standard library; the bounds let
// two cuts move between the outcomes (another library's distribution, a reader change that is still correct).
struct CutCounts {
  int cuts, read, reported, dropped;
};
constexpr int kCountSlack = 2;

void check_rinex_prefixes(const std::string& path, const std::string& cut_name, const CutCounts& measured) {
  PEDNAV_REQUIRE_DATA(path);
  const std::string text = read_all(path);
  // All systems: the last satellite line of a record (the one RTKLIB would decode cut) is usually not a GPS one.
  const gnss::SystemSelection gps{true, true, true, true, true};
  // Reference: the first kPrefixBytes + a bit, cut at a line end (its last record may be incomplete: dropped by RTKLIB).
  const std::string ref_path = write_cut("ref_" + cut_name, text, text.find('\n', kPrefixBytes + 1000) + 1);
  auto full = gnss::read_rinex_obs(ref_path, gps);
  ASSERT_TRUE(full) << full.error().message;
  int ok = 0, reported = 0, dropped = 0;
  const std::vector<size_t> cuts = cuts_in(text, text.find("END OF HEADER"));
  for (size_t cut : cuts) {
    auto r = gnss::read_rinex_obs(write_cut(cut_name, text, cut), gps);
    if (!r) {
      EXPECT_THAT(r.error().message, HasSubstr(cut_name)) << "cut at " << cut;
      continue;
    }
    ++ok;
    const bool mid_line = text[cut - 1] != '\n';
    if (mid_line) {
      EXPECT_TRUE(r->stats.truncated) << "cut at " << cut;
    }
    reported += r->stats.truncated;
    dropped += r->stats.last_epoch_dropped;
    ASSERT_LE(r->epochs.size(), full->epochs.size());
    for (size_t i = 0; i < r->epochs.size(); ++i) {
      const auto& a = r->epochs[i];
      const auto& b = full->epochs[i];
      ASSERT_EQ(a.time, b.time) << "cut at " << cut;
      ASSERT_EQ(a.sats.size(), b.sats.size()) << "cut at " << cut << ", epoch " << a.time.to_string();
      for (size_t k = 0; k < a.sats.size(); ++k) {
        ASSERT_TRUE(same(a.sats[k].pseudorange_m, b.sats[k].pseudorange_m))
            << "cut at " << cut << ": epoch " << a.time.to_string() << " pseudorange " << a.sats[k].pseudorange_m
            << " vs " << b.sats[k].pseudorange_m;
        ASSERT_TRUE(same(a.sats[k].doppler_hz, b.sats[k].doppler_hz)) << "cut at " << cut;
        ASSERT_TRUE(same(a.sats[k].cn0_dbhz, b.sats[k].cn0_dbhz)) << "cut at " << cut;
      }
    }
  }
  EXPECT_GT(ok, kCuts / 2);
  EXPECT_GT(reported, 0);
  std::printf("[ robust ] %s: %d cuts, %d read (%d reported truncated, %d with the cut last epoch dropped)\n",
              cut_name.c_str(), static_cast<int>(cuts.size()), ok, reported, dropped);
  EXPECT_EQ(static_cast<int>(cuts.size()), measured.cuts);
  EXPECT_GE(ok, measured.read - kCountSlack);
  EXPECT_NEAR(reported, measured.reported, kCountSlack);
  EXPECT_NEAR(dropped, measured.dropped, kCountSlack);
}

TEST(RobustRealDataTruncation, SeptentrioRinex3CutAnywhereGivesAPrefix) {
  check_rinex_prefixes(shared_data("gnss_septentrio_static_shortbaseline/rover.obs"), "sept_cut.obs", {50, 47, 47, 3});
}

TEST(RobustRealDataTruncation, Glw1Rinex2CutAnywhereGivesAPrefix) {
  check_rinex_prefixes(shared_data("gnss_ublox_m8p_walk_galway/cors_glw1/glw1277m.18o"), "glw1_cut.18o",
                       {50, 49, 49, 49});
}

TEST(RobustRealDataTruncation, XioImuLogCutAnywhereGivesAPrefix) {
  const std::string path = shared_data("foot_xio_ngimu_loops/short_walk.csv");
  PEDNAV_REQUIRE_DATA(path);
  auto fmt = io::imu_format_preset("xio_ngimu");
  ASSERT_TRUE(fmt) << fmt.error().message;
  const std::string text = read_all(path);
  const std::string head = text.substr(0, text.find('\n', kPrefixBytes + 1000) + 1);
  auto full = io::parse_imu_csv(head.data(), head.size(), "short_walk.csv", *fmt);
  ASSERT_TRUE(full) << full.error().message;
  int ok = 0;
  for (size_t cut : cuts_in(text, 0)) {
    auto r = io::parse_imu_csv(text.data(), cut, "short_walk.csv", *fmt);
    if (!r) {
      EXPECT_THAT(r.error().message, HasSubstr("short_walk.csv")) << "cut at " << cut;
      continue;
    }
    ++ok;
    EXPECT_EQ(r->report.truncated_rows, text[cut - 1] != '\n' ? 1 : 0);
    ASSERT_LE(r->samples.size(), full->samples.size());
    for (size_t i = 0; i < r->samples.size(); ++i) {
      ASSERT_EQ(r->samples[i].t, full->samples[i].t);
      ASSERT_EQ(r->samples[i].omega_ib_b, full->samples[i].omega_ib_b) << "cut at " << cut;
      ASSERT_EQ(r->samples[i].f_ib_b, full->samples[i].f_ib_b) << "cut at " << cut;
    }
  }
  std::printf("[ robust ] short_walk.csv: %d read\n", ok);
  EXPECT_GT(ok, kCuts / 2);
  EXPECT_GE(ok, 50 - kCountSlack);  // measured 2026-12-05: all 50 cuts read
}

}  // namespace
}  // namespace pednav
