// SPDX-License-Identifier: BSD-2-Clause
// `pednav gnss` on the real data sets: the "Done when" figures of issue 3 (docs/results.md), and bad inputs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <fstream>
#include <map>
#include <sstream>

#include "core/geodesy.hpp"
#include "gnss/types.hpp"
#include "io/config.hpp"
#include "pipeline/gnss_command.hpp"
#include "tests/support/data.hpp"

namespace pednav::pipeline {
namespace {

using namespace pednav::io;

using ::testing::HasSubstr;
using test::shared_data;

// Issue 3 thresholds.
constexpr double kGalwayMinSolvedPct = 99.5;
constexpr double kGalway2dRms_m = 2.0;
constexpr double kGalway2dP95_m = 3.2;
constexpr double kGalway2dMax_m = 8.0;
constexpr double kSpirent2dRms_m = 0.05;
constexpr double kSeptentrioVelRms_mps = 0.05;
// Issue target 0.36 m (RTKLIB DGPS); measured 0.295 m with the default 10 s Doppler smoothing (0.375 m without).
constexpr double kSeptentrio2dRms_m = 0.36;
constexpr double kTimeMatch_s = 0.1;
// Figures measured 2026-12-05 (Release; `pednav gnss` is deterministic), checked beside the issue's thresholds with
// +20 % (+30 % for Spirent's centimetre figures): a change of the solver (weights, exclusion, smoothing) that stays
// inside issue 3's thresholds still shows. Horizontal RMS / p95 / max [m].
struct Measured2d {
  double rms, p95, max;
};
constexpr double kMargin = 1.2;
constexpr Measured2d kGalwayG{1.356, 2.690, 4.234};
constexpr Measured2d kGalwayGR{1.279, 2.272, 3.454};
constexpr Measured2d kGalwayGlw1{1.754, 2.534, 4.104};
constexpr double kSpirentRms_m = 0.0122, kSpirentMax_m = 0.0162, kSpirentMargin = 1.3;
constexpr double kSeptentrioRms_m = 0.2946, kSeptentrioVelRms_m = 0.0273;

const std::string kGalway = "gnss_ublox_m8p_walk_galway/";

struct Stats {
  int compared = 0;
  double rms = 0, p95 = 0, max = 0;
};

Stats stats_of(std::vector<double> e) {
  Stats s;
  s.compared = static_cast<int>(e.size());
  if (e.empty()) return s;
  std::sort(e.begin(), e.end());
  double sum = 0;
  for (double v : e) sum += v * v;
  s.rms = std::sqrt(sum / e.size());
  s.p95 = e[static_cast<size_t>(std::ceil(0.95 * e.size())) - 1];
  s.max = e.back();
  return s;
}

struct CsvRow {
  double tow_s;
  Eigen::Vector3d p_e, v_n;
  std::string status;  // solution_status (with carrier)
};

std::vector<CsvRow> read_gnss_csv(const std::string& path) {
  std::vector<CsvRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    CsvRow r;
    r.tow_s = std::stod(c[1]);
    r.p_e = Eigen::Vector3d(std::stod(c[5]), std::stod(c[6]), std::stod(c[7]));
    r.v_n = c[8].empty() ? Eigen::Vector3d::Constant(gnss::kNaN) : Eigen::Vector3d(std::stod(c[8]), std::stod(c[9]), std::stod(c[10]));
    if (c.size() > 23) r.status = c[23];
    rows.push_back(r);
  }
  return rows;
}

// RTK-fixed GGA epochs (quality 4) of the Galway rover: GPST time of day [s] -> ECEF [m] (h = alt + geoid sep).
std::map<long, Eigen::Vector3d> galway_truth() {
  std::map<long, Eigen::Vector3d> t;
  std::ifstream in(shared_data(kGalway + "reference_nmea/rover-20181004-1532.nmea"));
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("$GNGGA", 0) != 0) continue;
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    if (c.size() < 12 || c[6] != "4") continue;
    const double tod = std::stod(c[1].substr(0, 2)) * 3600 + std::stod(c[1].substr(2, 2)) * 60 + std::stod(c[1].substr(4));
    const double lat = (std::stod(c[2].substr(0, 2)) + std::stod(c[2].substr(2)) / 60) * (c[3] == "N" ? 1 : -1);
    const double lon = (std::stod(c[4].substr(0, 3)) + std::stod(c[4].substr(3)) / 60) * (c[5] == "E" ? 1 : -1);
    const double h = std::stod(c[9]) + std::stod(c[11]);
    t[std::lround(tod + 18.0)] = ecef_from_geodetic({lat * kDegToRad, lon * kDegToRad, h});  // UTC = GPST - 18 s
  }
  return t;
}

Stats galway_errors(const std::string& csv) {
  const auto truth = galway_truth();
  std::vector<double> e;
  for (const auto& r : read_gnss_csv(csv)) {
    const double tod = std::fmod(r.tow_s, 86400.0);
    auto it = truth.find(std::lround(tod));
    if (it == truth.end() || std::abs(tod - it->first) > kTimeMatch_s) continue;
    const Eigen::Vector3d enu = enu_from_ecef(r.p_e, it->second);
    e.push_back(std::hypot(enu.x(), enu.y()));
  }
  return stats_of(e);
}

std::string out_dir(const std::string& name) {
  return ::testing::TempDir() + "pednav_gnss_" + name;
}

Expected<GnssRunSummary> run(const std::string& yaml, const std::string& name) {
  auto cfg = parse_run_config(yaml, name + ".yaml", "/");
  if (!cfg) return cfg.error();
  return run_gnss_command(*cfg, out_dir(name));
}

std::string galway_yaml(const std::string& systems, const std::string& base_obs = "rinex/base-20181004-1452.obs",
                        const std::string& base_pos = "[3774085.6456, -601662.5769, 5089316.3970]",
                        const std::string& extra_nav = "") {
  return "mode: gnss\nrover_obs: " + shared_data(kGalway + "rinex/rover-20181004-1532.obs") +
         "\nbase_obs: " + shared_data(kGalway + base_obs) + "\nnav: [" +
         shared_data(kGalway + "rinex/base-20181004-1452.nav") + extra_nav + "]\nbase_position_ecef_m: " + base_pos +
         "\ngnss:\n  carrier: off\n  systems: " + systems + "\n";
}

void expect_measured(const Stats& s, const Measured2d& m, const char* what) {
  EXPECT_LT(s.rms, kMargin * m.rms) << what;
  EXPECT_LT(s.p95, kMargin * m.p95) << what;
  EXPECT_LT(s.max, kMargin * m.max) << what;
}

TEST(GnssCommandData, GalwayM8pBaseGps) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1532.obs"));
  auto sum = run(galway_yaml("[G]"), "galway_g");
  ASSERT_TRUE(sum) << sum.error().message;
  EXPECT_EQ(sum->epochs_read, 1180);
  EXPECT_GE(100.0 * sum->epochs_solved / sum->epochs_read, kGalwayMinSolvedPct);
  const Stats s = galway_errors(out_dir("galway_g") + "/gnss.csv");
  std::printf("[galway G] solved %d/%d, 2D RMS %.3f p95 %.3f max %.3f m\n", sum->epochs_solved, sum->epochs_read, s.rms,
              s.p95, s.max);
  EXPECT_EQ(s.compared, 552);
  EXPECT_LE(s.rms, kGalway2dRms_m);
  EXPECT_LE(s.p95, kGalway2dP95_m);
  EXPECT_LE(s.max, kGalway2dMax_m);
  expect_measured(s, kGalwayG, "galway G");
  EXPECT_GT(sum->base_age.max_s, 5.0);  // the irregular base forces old-epoch use
  EXPECT_TRUE(std::filesystem::exists(out_dir("galway_g") + "/gnss.pos"));
  EXPECT_TRUE(std::filesystem::exists(out_dir("galway_g") + "/summary.json"));
}

TEST(GnssCommandData, GalwayGpsGlonassNoWorseThanGps) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1532.obs"));
  auto g = run(galway_yaml("[G]"), "galway_g2");
  auto gr = run(galway_yaml("[G, R]"), "galway_gr");
  ASSERT_TRUE(g && gr);
  const Stats sg = galway_errors(out_dir("galway_g2") + "/gnss.csv");
  const Stats sgr = galway_errors(out_dir("galway_gr") + "/gnss.csv");
  std::printf("[galway G+R] solved %d, 2D RMS %.3f p95 %.3f max %.3f m (G: %.3f %.3f %.3f)\n", gr->epochs_solved, sgr.rms,
              sgr.p95, sgr.max, sg.rms, sg.p95, sg.max);
  EXPECT_GE(gr->epochs_solved, g->epochs_solved);
  EXPECT_LE(sgr.rms, sg.rms);
  EXPECT_LE(sgr.p95, sg.p95);
  EXPECT_LE(sgr.max, sg.max);
  EXPECT_EQ(gr->epochs_solved, 1180);
  expect_measured(sgr, kGalwayGR, "galway G+R");
  expect_measured(sg, kGalwayG, "galway G");
  EXPECT_GT(gr->satellites_rejected.at("code_fault_excluded"), 0);  // exclusion is what earns it
}

TEST(GnssCommandData, GalwayAgainstCorsGlw1) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "cors_glw1/glw1277p.18o"));
  auto sum = run(galway_yaml("[G]", "cors_glw1/glw1277p.18o", "[3774050.9626, -601852.6734, 5089350.3688]",
                             ", " + shared_data(kGalway + "cors_glw1/glw1277p.18n")),
                 "galway_glw1");
  ASSERT_TRUE(sum) << sum.error().message;
  const Stats s = galway_errors(out_dir("galway_glw1") + "/gnss.csv");
  std::printf("[galway GLW1] solved %d, 2D RMS %.3f p95 %.3f max %.3f m\n", sum->epochs_solved, s.rms, s.p95, s.max);
  EXPECT_EQ(sum->epochs_solved, 1180);
  EXPECT_LE(s.rms, kGalway2dRms_m);
  EXPECT_LE(s.p95, kGalway2dP95_m);
  EXPECT_LE(s.max, kGalway2dMax_m);
  expect_measured(s, kGalwayGlw1, "galway GLW1");
}

// Spirent truth at 10 Hz: round(GpsToW · 10) -> ECEF (columns 3..6 of the PVA file in folder d).
std::map<long, Eigen::Vector3d> spirent_truth(const std::string& d) {
  std::map<long, Eigen::Vector3d> truth;
  std::ifstream in(d + "Rover-dynamic_PVA_Spirent.csv");
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<double> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(std::stod(cell));
    truth[std::lround(c[3] * 10)] = Eigen::Vector3d(c[4], c[5], c[6]);
  }
  return truth;
}

// The Spirent dynamic rover against its base (Klobuchar/Saastamoinen folder) in folder d, then `gnss_section`.
std::string spirent_yaml(const std::string& d, const std::string& gnss_section) {
  return "mode: gnss\nrover_obs: " + d + "iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs\n" + "base_obs: " + d +
         "iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs\nnav: [" + d + "RINEX_GN_Spirent.23N, " + d +
         "RINEX_EN_Spirent.23L]\n" + "base_position_ecef_m: [4157177.06580187, 671230.476590636, 4774767.03105544]\n" +
         gnss_section;
}

TEST(GnssCommandData, SpirentDynamicNoiseFree) {
  const std::string d = shared_data("rtklib_samples/instinct_spirent_rtk_GE/");
  PEDNAV_REQUIRE_DATA(d + "Rover-dynamic_PVA_Spirent.csv");
  const std::string yaml = spirent_yaml(d, "gnss:\n  carrier: off\n  systems: [G, E]\n");
  auto sum = run(yaml, "spirent");
  ASSERT_TRUE(sum) << sum.error().message;
  EXPECT_EQ(sum->epochs_solved, 601);
  const std::map<long, Eigen::Vector3d> truth = spirent_truth(d);
  std::vector<double> e;
  for (const auto& r : read_gnss_csv(out_dir("spirent") + "/gnss.csv")) {
    auto it = truth.find(std::lround(r.tow_s * 10));
    if (it == truth.end()) continue;
    const Eigen::Vector3d enu = enu_from_ecef(r.p_e, it->second);
    e.push_back(std::hypot(enu.x(), enu.y()));
  }
  const Stats s = stats_of(e);
  std::printf("[spirent] 2D RMS %.4f max %.4f m over %d epochs\n", s.rms, s.max, s.compared);
  EXPECT_EQ(s.compared, 601);
  EXPECT_LE(s.rms, kSpirent2dRms_m);
  EXPECT_LT(s.rms, kSpirentMargin * kSpirentRms_m);
  EXPECT_LT(s.max, kSpirentMargin * kSpirentMax_m);
}

TEST(GnssCommandData, SeptentrioStaticShortBaseline) {
  const std::string d = shared_data("gnss_septentrio_static_shortbaseline/");
  PEDNAV_REQUIRE_DATA(d + "rover.obs");
  const std::string yaml = "mode: gnss\nrover_obs: " + d + "rover.obs\nbase_obs: " + d + "base.obs\nnav: [" + d +
                           "base.nav]\nbase_position_ecef_m: [-3817681.1213, 3562839.4311, 3650159.1593]\n" +
                           "gnss:\n  carrier: off\n  systems: [G]\n";
  auto sum = run(yaml, "septentrio");
  ASSERT_TRUE(sum) << sum.error().message;
  const Eigen::Vector3d truth(-3817681.3807, 3562839.9785, 3650158.3760);
  std::vector<double> e;
  double v2 = 0;
  int nv = 0;
  for (const auto& r : read_gnss_csv(out_dir("septentrio") + "/gnss.csv")) {
    const Eigen::Vector3d enu = enu_from_ecef(r.p_e, truth);
    e.push_back(std::hypot(enu.x(), enu.y()));
    if (!std::isnan(r.v_n.x())) v2 += r.v_n.squaredNorm(), ++nv;
  }
  std::printf("[septentrio] 2D RMS %.4f m, velocity RMS %.4f m/s\n", stats_of(e).rms, nv ? std::sqrt(v2 / nv) : 0.0);
  EXPECT_EQ(static_cast<int>(e.size()), 301);
  EXPECT_LE(stats_of(e).rms, kSeptentrio2dRms_m);
  ASSERT_GT(nv, 290);
  EXPECT_LE(std::sqrt(v2 / nv), kSeptentrioVelRms_mps);
  EXPECT_LT(stats_of(e).rms, kMargin * kSeptentrioRms_m);
  EXPECT_LT(std::sqrt(v2 / nv), kMargin * kSeptentrioVelRms_m);
}

TEST(GnssCommandData, GeonetEveryEpochSolvedDespiteClockJumps) {
  const std::string d = shared_data("rtklib_samples/rtklib_b34_geonet_gps/");
  PEDNAV_REQUIRE_DATA(d + "07590920.05o");
  const std::string yaml = "mode: gnss\nrover_obs: " + d + "07590920.05o\nbase_obs: " + d + "30400920.05o\nnav: [" + d +
                           "07590920.05n, " + d + "30400920.05n]\n";
  auto sum = run(yaml, "geonet");
  ASSERT_TRUE(sum) << sum.error().message;
  EXPECT_EQ(sum->epochs_read, 120);
  EXPECT_EQ(sum->epochs_solved, 120);
  EXPECT_TRUE(sum->base_position_from_header);
  // The jumps: the rover's receiver steps its clock +1 ms at a time (epoch time tags x.000 ... x.005 s), the base's
  // -1 ms (x.999 ... x.996 s), so rover and base tags of the same epoch drift apart by up to 9 ms (read from the
  // files, 2026-12-06: 108 of the 120 epochs at least 1 ms apart, mean 4.3 ms). Without the jumps every age would be 0.
  std::printf("[geonet] base age: %d matched, mean %.4f s, median %.4f s, max %.4f s\n", sum->base_age.matched,
              sum->base_age.mean_s, sum->base_age.median_s, sum->base_age.max_s);
  EXPECT_EQ(sum->base_age.matched, 120);
  EXPECT_NEAR(sum->base_age.max_s, 0.009, 1e-6);
  EXPECT_NEAR(sum->base_age.mean_s, 0.0043, 1e-4);
}

// ---- bad inputs ----

TEST(GnssCommandBadInput, MissingEmptyAndTruncatedObs) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1532.obs"));
  auto missing = run(galway_yaml("[G]", "rinex/nonexistent.obs"), "bad_missing");
  ASSERT_FALSE(missing);
  // Checked before any processing, naming the key (io::missing_input_files).
  EXPECT_THAT(missing.error().message, HasSubstr("base_obs: " + shared_data(kGalway + "rinex/nonexistent.obs") + " does not exist"));

  const std::string empty = ::testing::TempDir() + "pednav_gnss_empty.obs";
  { std::ofstream(empty).close(); }
  std::string yaml = galway_yaml("[G]");
  const std::string rover = shared_data(kGalway + "rinex/rover-20181004-1532.obs");
  auto with_rover = [&](const std::string& path) {
    std::string y = yaml;
    y.replace(y.find(rover), rover.size(), path);
    return y;
  };
  auto e = run(with_rover(empty), "bad_empty");
  ASSERT_FALSE(e);
  EXPECT_THAT(e.error().message, HasSubstr("pednav_gnss_empty.obs: file is empty"));

  // Cut the rover file in the middle of an epoch record.
  const std::string cut = ::testing::TempDir() + "pednav_gnss_cut.obs";
  {
    std::ifstream in(rover, std::ios::binary);
    std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t at = all.find('>', all.size() / 2);
    std::ofstream(cut, std::ios::binary) << all.substr(0, all.find('\n', all.find('\n', at) + 1) + 1);
  }
  auto t = run(with_rover(cut), "bad_cut");
  ASSERT_FALSE(t);
  EXPECT_THAT(t.error().message, HasSubstr("pednav_gnss_cut.obs: truncated"));
}

TEST(GnssCommandBadInput, NavNotCoveringTheSpan) {
  PEDNAV_REQUIRE_DATA(shared_data("rtklib_samples/rtklib_b34_geonet_gps/07590920.05n"));
  std::string yaml = galway_yaml("[G]");
  const std::string nav = shared_data(kGalway + "rinex/base-20181004-1452.nav");
  yaml.replace(yaml.find(nav), nav.size(), shared_data("rtklib_samples/rtklib_b34_geonet_gps/07590920.05n"));
  auto r = run(yaml, "bad_nav");
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("navigation data do not cover the rover span"));
}

TEST(GnssCommandBadInput, BaseFromAnotherDay) {
  PEDNAV_REQUIRE_DATA(shared_data("rtklib_samples/rtklib_b34_geonet_gps/30400920.05o"));
  std::string yaml = galway_yaml("[G]");
  const std::string base = shared_data(kGalway + "rinex/base-20181004-1452.obs");
  yaml.replace(yaml.find(base), base.size(), shared_data("rtklib_samples/rtklib_b34_geonet_gps/30400920.05o"));
  auto r = run(yaml, "bad_day");
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("base file from another day"));
}

TEST(GnssCommandBadInput, NoCommonSatellites) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1532.obs"));
  // A base copy whose GPS records are relabelled GLONASS: with systems [G] rover and base share no satellite.
  const std::string base = shared_data(kGalway + "rinex/base-20181004-1452.obs");
  const std::string renamed = ::testing::TempDir() + "pednav_gnss_renamed_base.obs";
  {
    std::ifstream in(base);
    std::ofstream out(renamed);
    std::string line;
    bool header = true;
    while (std::getline(in, line)) {
      if (!header && line.size() > 3 && line[0] == 'G') line[0] = 'R';
      if (line.find("END OF HEADER") != std::string::npos) header = false;
      out << line << '\n';
    }
  }
  std::string yaml = galway_yaml("[G]");
  yaml.replace(yaml.find(base), base.size(), renamed);
  auto r = run(yaml, "bad_common");
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("no common satellites"));
}


// ---- Carrier phase: kinematic RTK in `pednav gnss` (issue 48, docs/carrier.md §4, docs/results.md "Carrier phase").
namespace rtk {

struct Scored {
  int fixed = 0, epochs = 0, fixed_compared = 0, wrong = 0;  // wrong: fixed epochs > kWrongFix_m from the reference
  Stats all, on_fixed;
};
constexpr double kWrongFix_m = 0.10;  // the issue's definition of a wrong fix on the Galway walk

// Score a gnss.csv against reference positions; key(tow) gives a row's key in `truth`; `offset_e` [m, ECEF] is
// subtracted from every solution position (a reference frame offset).
Scored score(const std::string& csv, const std::map<long, Eigen::Vector3d>& truth, const std::function<long(double)>& key,
             const Eigen::Vector3d& offset_e = Eigen::Vector3d::Zero()) {
  Scored s;
  std::vector<double> all, fixed;
  for (const auto& r : read_gnss_csv(csv)) {
    ++s.epochs;
    const bool is_fixed = r.status == "fixed";
    s.fixed += is_fixed;
    auto it = truth.find(key(r.tow_s));
    if (it == truth.end()) continue;
    const Eigen::Vector3d enu = enu_from_ecef(r.p_e - offset_e, it->second);
    const double h = std::hypot(enu.x(), enu.y());
    all.push_back(h);
    if (!is_fixed) continue;
    fixed.push_back(h);
    s.wrong += h > kWrongFix_m;
  }
  s.fixed_compared = static_cast<int>(fixed.size());
  s.all = stats_of(all);
  s.on_fixed = stats_of(fixed);
  return s;
}

// Galway walk: galway_truth() is keyed by the GPST second of the day; the rover epochs are at .987 s.
long galway_key(double tow_s) { return std::lround(std::fmod(tow_s, 86400.0)); }

std::string galway_rtk_yaml(const std::string& extra) {
  return "mode: gnss\nrover_obs: " + shared_data(kGalway + "rinex/rover-20181004-1532.obs") +
         "\nbase_obs: " + shared_data(kGalway + "rinex/base-20181004-1452.obs") + "\nnav: [" +
         shared_data(kGalway + "rinex/base-20181004-1452.nav") +
         "]\nbase_position_ecef_m: [3774085.6456, -601662.5769, 5089316.3970]\n"
         "gnss:\n  systems: [G, R]\n  elevation_mask_deg: 15\n  min_cn0_dbhz: 35\n" + extra;
}

}  // namespace rtk

namespace rtk {
// Figures measured 2026-12-06 (Release, deterministic; the default of 6 double differences: with 4, 801 fixed, 5 of
// 444 wrong, 0.090 m, static 1130); bounds = the figure + the stated margin.
constexpr int kGalwayGloArFixed = 782;          // of 1179 solved epochs (Debian rnx2rtkp: 259; receiver: 552)
constexpr int kGalwayGloArFixedMargin = 39;     // −5 %
constexpr int kGalwayGloArWrong = 0;            // of 439 fixed epochs with a receiver-fixed reference
constexpr double kGalwayGloArFixedRms_m = 0.011, kRmsMargin = 1.2;
constexpr double kGalwayFloatRms_m = 0.606;     // default options (GLONASS float): 4 fixed epochs
constexpr double kSpirentFixedRms_m = 0.00010;  // noise-free simulator: 599 of 601 epochs fixed from the 3rd on
constexpr double kSpirentFixedRmsMargin_m = 0.0001;
constexpr int kStaticFixed = 1102;              // Galway static session, 1205 epochs
constexpr double kStaticRms_m = 0.020;
}  // namespace rtk

TEST(GnssRtkData, SpirentDynamicFixesEveryEpochAfterTheFirstFix) {
  const std::string d = shared_data("rtklib_samples/instinct_spirent_rtk_GE/");
  PEDNAV_REQUIRE_DATA(d + "Rover-dynamic_PVA_Spirent.csv");
  const std::string yaml = spirent_yaml(d, "gnss:\n  systems: [G, E]\n  elevation_mask_deg: 15\n");
  auto sum = run(yaml, "spirent_rtk");
  ASSERT_TRUE(sum) << sum.error().message;
  ASSERT_TRUE(sum->carrier);
  const std::map<long, Eigen::Vector3d> truth = spirent_truth(d);
  const auto s = rtk::score(out_dir("spirent_rtk") + "/gnss.csv", truth, [](double tow) { return std::lround(tow * 10); });
  std::printf("[spirent rtk] fixed %d of %d, horizontal RMS on fixed %.5f m, ttff %.0f s\n", s.fixed, s.epochs,
              s.on_fixed.rms, sum->rtk.time_to_first_fix_s.value_or(-1));
  ASSERT_TRUE(sum->rtk.time_to_first_fix_s.has_value());
  EXPECT_LE(*sum->rtk.time_to_first_fix_s, 2.0);
  EXPECT_EQ(s.fixed, s.epochs - 2);  // every epoch from the first fix on (issue: >= 95 %)
  EXPECT_LE(s.on_fixed.rms, rtk::kSpirentFixedRms_m + rtk::kSpirentFixedRmsMargin_m);  // issue: <= 0.005 m
  EXPECT_EQ(sum->rtk.wrong_fix_detections, 0);
}

TEST(GnssRtkData, GalwayWalkWithGlonassArBeatsTheRtklibPeer) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1532.obs"));
  // Rover and base are both u-blox M8P: their GLONASS inter-frequency biases cancel (gnss.ambiguity.glonass).
  auto sum = run(rtk::galway_rtk_yaml("  ambiguity: {glonass: true}\n"), "galway_rtk_gloar");
  ASSERT_TRUE(sum) << sum.error().message;
  ASSERT_TRUE(sum->carrier);
  const auto s = rtk::score(out_dir("galway_rtk_gloar") + "/gnss.csv", galway_truth(), rtk::galway_key);
  std::printf("[galway rtk glo-AR] fixed %d of %d; %d fixed epochs scored, %d wrong (> 0.10 m); RMS on fixed %.3f m, "
              "all %.3f m\n", s.fixed, s.epochs, s.fixed_compared, s.wrong, s.on_fixed.rms, s.all.rms);
  EXPECT_GE(s.fixed, rtk::kGalwayGloArFixed - rtk::kGalwayGloArFixedMargin);
  EXPECT_GT(s.fixed, 259);  // Debian rnx2rtkp with the peer configuration (../shared/notes/rtk_peer_galway.md)
  EXPECT_LE(s.wrong, rtk::kGalwayGloArWrong + 2);
  EXPECT_LT(s.on_fixed.rms, rtk::kRmsMargin * rtk::kGalwayGloArFixedRms_m);
}

TEST(GnssRtkData, GalwayWalkFloatBeatsTheCode) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1532.obs"));
  auto sum = run(rtk::galway_rtk_yaml("  ambiguity: {glonass_ifb: off}\n"), "galway_rtk_float");
  ASSERT_TRUE(sum) << sum.error().message;
  ASSERT_TRUE(sum->carrier);
  const auto s = rtk::score(out_dir("galway_rtk_float") + "/gnss.csv", galway_truth(), rtk::galway_key);
  std::printf("[galway rtk float] fixed %d, RMS %.3f m over %d epochs (code only G+R: %.3f m)\n", s.fixed, s.all.rms,
              s.all.compared, kGalwayGR.rms);
  EXPECT_LT(s.all.rms, rtk::kRmsMargin * rtk::kGalwayFloatRms_m);
  EXPECT_LT(s.all.rms, 0.5 * kGalwayGR.rms);
  // Slips are found and counted: the walk has loss-of-lock flags and half cycles under the trees.
  EXPECT_GT(sum->rtk.slips[static_cast<int>(gnss::SlipReason::kLossOfLock)], 0);
  EXPECT_GT(sum->rtk.slips[static_cast<int>(gnss::SlipReason::kHalfCycle)], 0);
}

TEST(GnssRtkData, GalwayStaticSessionFixes) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1237.obs"));
  const std::string yaml = "mode: gnss\nrover_obs: " + shared_data(kGalway + "rinex/rover-20181004-1237.obs") +
                           "\nbase_obs: " + shared_data(kGalway + "rinex/base-20181004-1236.obs") + "\nnav: [" +
                           shared_data(kGalway + "rinex/base-20181004-1236.nav") +
                           "]\nbase_position_ecef_m: [3774089.2120, -601661.6157, 5089321.2474]\n"
                           "gnss:\n  systems: [G, R]\n  elevation_mask_deg: 15\n  min_cn0_dbhz: 35\n";
  auto sum = run(yaml, "galway_static_rtk");
  ASSERT_TRUE(sum) << sum.error().message;
  std::printf("[galway static rtk] fixed %d of %d epochs\n", sum->rtk.fixed, sum->rtk.epochs);
  EXPECT_GE(sum->rtk.fixed, rtk::kStaticFixed - 40);
  EXPECT_EQ(sum->rtk.wrong_fix_detections, 0);
}

// The defaults on the Galway walk with its M8P base (two receivers of one type): the search of docs/carrier.md §3.1
// finds β = 0 and GLONASS is fixed without `glonass: true`. Measured 2026-12-06: β 0.0000 after 67 s (10 votes in 66
// searches), 773 of 1179 fixed, 0 of 439 scored wrong, 0.011 m RMS on fixed (with `glonass: true`: 782, 0 of 439).
TEST(GnssRtkData, GalwayWalkDefaultsFindNoGlonassBiasBetweenTwoM8p) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1532.obs"));
  auto sum = run(rtk::galway_rtk_yaml(""), "galway_rtk_defaults");
  ASSERT_TRUE(sum) << sum.error().message;
  ASSERT_TRUE(sum->rtk.glonass_ifb_m_per_channel.has_value());
  const auto s = rtk::score(out_dir("galway_rtk_defaults") + "/gnss.csv", galway_truth(), rtk::galway_key);
  std::printf("[galway rtk defaults] beta %.4f m per channel after %.0f s; fixed %d of %d; %d scored, %d wrong; RMS on "
              "fixed %.3f m\n", *sum->rtk.glonass_ifb_m_per_channel, sum->rtk.glonass_ifb_found_s.value_or(-1.0), s.fixed,
              s.epochs, s.fixed_compared, s.wrong, s.on_fixed.rms);
  EXPECT_NEAR(*sum->rtk.glonass_ifb_m_per_channel, 0.0, 0.0025);
  EXPECT_LE(sum->rtk.glonass_ifb_found_s.value_or(1e9), 1.2 * 67.0);
  EXPECT_GE(s.fixed, 773 - 38);
  EXPECT_LE(s.wrong, 2);
  EXPECT_LT(s.on_fixed.rms, rtk::kRmsMargin * 0.011);
}

// The Galway rover on CORS GLW1 (a Leica GR30 196 m away, RINEX 2.11 at 5 s, no Doppler; issue 48): u-blox and Leica
// GLONASS phases differ by an inter-frequency bias β k, so GLONASS can be fixed only once β is known; with
// gnss.ambiguity.glonass_ifb: search it is found (docs/carrier.md eqs. 3.9-3.11). Scored against the receiver's fixed
// GGA epochs after removing the mean offset of the fixed epochs (the receiver's RTK frame is ≈ 1.2 m from GLW1's).
// Measured 2026-12-06 (GLW1 was looked at when the search's constants were set: docs/carrier.md §7): β = −0.0525 m per channel after 56 s (10 votes in 55
// searches); 617 of 1179 epochs fixed (52 %), 0 of 375 scored wrong, 0.013 m RMS on fixed, offset −0.41 m east,
// −1.14 m north; without the search 0 fixed (GPS alone never has the 6 double differences). Bounds: fixed −5 %,
// wrong the issue's 1 %, RMS +20 %, β ± one grid step.
TEST(GnssRtkData, GalwayWalkOnCorsGlw1FindsTheGlonassInterFrequencyBias) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "cors_glw1/glw1277p.18o"));
  const std::string yaml = rtk::galway_rtk_yaml("  ambiguity: {glonass_ifb: search}\n");
  const std::string glw1 = "mode: gnss\nrover_obs: " + shared_data(kGalway + "rinex/rover-20181004-1532.obs") +
                           "\nbase_obs: " + shared_data(kGalway + "cors_glw1/glw1277p.18o") + "\nnav: [" +
                           shared_data(kGalway + "rinex/base-20181004-1452.nav") + ", " +
                           shared_data(kGalway + "cors_glw1/glw1277p.18n") +
                           "]\nbase_position_ecef_m: [3774050.9626, -601852.6734, 5089350.3688]\n" +
                           yaml.substr(yaml.find("gnss:\n"));
  auto sum = run(glw1, "galway_glw1_rtk");
  ASSERT_TRUE(sum) << sum.error().message;
  ASSERT_TRUE(sum->carrier);
  ASSERT_TRUE(sum->rtk.glonass_ifb_m_per_channel.has_value());
  const auto truth = galway_truth();
  std::vector<Eigen::Vector3d> enu;
  int fixed = 0, epochs = 0;
  for (const auto& r : read_gnss_csv(out_dir("galway_glw1_rtk") + "/gnss.csv")) {
    ++epochs;
    if (r.status != "fixed") continue;
    ++fixed;
    auto it = truth.find(rtk::galway_key(r.tow_s));
    if (it != truth.end()) enu.push_back(enu_from_ecef(r.p_e, it->second));
  }
  ASSERT_FALSE(enu.empty());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& e : enu) mean += e;
  mean /= static_cast<double>(enu.size());
  int wrong = 0;
  double sum_sq = 0.0;
  for (const auto& e : enu) {
    const double h = std::hypot(e.x() - mean.x(), e.y() - mean.y());
    wrong += h > rtk::kWrongFix_m;
    sum_sq += h * h;
  }
  const double rms = std::sqrt(sum_sq / static_cast<double>(enu.size()));
  std::printf("[galway GLW1 rtk] beta %.4f m per channel after %.0f s (%d votes in %d searches); fixed %d of %d; %zu "
              "scored, %d wrong; RMS on fixed %.3f m after the offset %.2f m east, %.2f m north\n",
              *sum->rtk.glonass_ifb_m_per_channel, sum->rtk.glonass_ifb_found_s.value_or(-1.0),
              sum->rtk.glonass_ifb_votes, sum->rtk.glonass_ifb_searches, fixed, epochs, enu.size(), wrong, rms,
              mean.x(), mean.y());
  EXPECT_NEAR(*sum->rtk.glonass_ifb_m_per_channel, -0.0525, 0.0025);
  EXPECT_LE(sum->rtk.glonass_ifb_found_s.value_or(1e9), 1.2 * 56.0);
  EXPECT_GE(fixed, 617 - 31);
  EXPECT_GE(100.0 * fixed, 25.0 * epochs);  // issue 48: >= 25 % fixed
  EXPECT_LE(100.0 * wrong, 1.0 * static_cast<double>(enu.size()));  // issue 48: <= 1 % wrong
  EXPECT_LT(rms, rtk::kRmsMargin * 0.013);
  EXPECT_NEAR(mean.x(), -0.41, 0.05);
  EXPECT_NEAR(mean.y(), -1.14, 0.05);
  EXPECT_EQ(sum->rtk.wrong_fix_detections, 0);
}

// The Galway rover alone (no base): the TDCP filter (docs/carrier.md §9) against the epoch least squares, scored on the
// receiver's RTK-fixed epochs: the absolute error (code level for both) and the error of each 1-s displacement
// between two consecutive fixed epochs (the carrier's figure).
TEST(GnssRtkData, GalwayRoverAloneTdcpDisplacement) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1532.obs"));
  const auto truth = galway_truth();
  auto yaml = [](const std::string& carrier) {
    return "mode: gnss\nrover_obs: " + shared_data(kGalway + "rinex/rover-20181004-1532.obs") + "\nnav: [" +
           shared_data(kGalway + "rinex/base-20181004-1452.nav") +
           "]\ngnss:\n  systems: [G, R]\n  elevation_mask_deg: 15\n  min_cn0_dbhz: 35\n  carrier: " + carrier + "\n";
  };
  struct Figures {
    Stats absolute, displacement;
  };
  auto figures = [&](const std::string& name) {
    std::map<long, Eigen::Vector3d> sol;
    for (const auto& r : read_gnss_csv(out_dir(name) + "/gnss.csv")) sol[rtk::galway_key(r.tow_s)] = r.p_e;
    std::vector<double> a, d;
    for (const auto& [k, p] : sol) {
      auto t = truth.find(k);
      if (t == truth.end()) continue;
      const Eigen::Vector3d e = enu_from_ecef(p, t->second);
      a.push_back(std::hypot(e.x(), e.y()));
      auto s1 = sol.find(k + 1);
      auto t1 = truth.find(k + 1);
      if (s1 == sol.end() || t1 == truth.end()) continue;
      const Eigen::Vector3d e1 = enu_from_ecef(s1->second, t1->second);
      d.push_back(std::hypot(e1.x() - e.x(), e1.y() - e.y()));
    }
    return Figures{stats_of(a), stats_of(d)};
  };
  auto on = run(yaml("auto"), "galway_tdcp");
  ASSERT_TRUE(on) << on.error().message;
  ASSERT_TRUE(on->tdcp);
  auto off = run(yaml("off"), "galway_tdcp_off");
  ASSERT_TRUE(off) << off.error().message;
  const Figures f_on = figures("galway_tdcp"), f_off = figures("galway_tdcp_off");
  std::printf("[galway rover alone] 1-s displacement RMS: least squares %.3f m, TDCP filter %.3f m (%d pairs); absolute "
              "RMS %.3f / %.3f m; TDCP rows on %d of %d epochs\n", f_off.displacement.rms, f_on.displacement.rms,
              f_on.displacement.compared, f_off.absolute.rms, f_on.absolute.rms, on->tdcp_summary.tdcp_epochs,
              on->tdcp_summary.epochs);
  // Measured 2026-12-06 (Release, deterministic): 0.236 → 0.022 m (533 pairs), absolute 1.844 / 1.631 m; TDCP rows on
  // 1159 of 1180 epochs. Bounds: + 20 % on the TDCP figures; the 10.7x gain at least halved.
  EXPECT_LT(f_on.displacement.rms, 1.2 * 0.022);
  EXPECT_GT(f_off.displacement.rms / f_on.displacement.rms, 5.3);
  EXPECT_LT(f_on.absolute.rms, 1.2 * 1.631);
  EXPECT_GT(f_on.displacement.compared, 500);
  EXPECT_GT(on->tdcp_summary.tdcp_epochs, 1100);
}

TEST(GnssRtkData, CarrierOnWithoutBaseRunsTheTdcpFilter) {
  PEDNAV_REQUIRE_DATA(shared_data(kGalway + "rinex/rover-20181004-1532.obs"));
  // `gnss.carrier: on` without a base: the rover's phase differenced over time (docs/carrier.md §9), not an error.
  const std::string yaml = "mode: gnss\nrover_obs: " + shared_data(kGalway + "rinex/rover-20181004-1532.obs") +
                           "\nnav: [" + shared_data(kGalway + "rinex/base-20181004-1452.nav") +
                           "]\ngnss:\n  carrier: on\n";
  auto sum = run(yaml, "carrier_on_no_base");
  ASSERT_TRUE(sum) << sum.error().message;
  EXPECT_TRUE(sum->tdcp);
  EXPECT_FALSE(sum->carrier);
}

}  // namespace
}  // namespace pednav::pipeline
