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
#include "tests/pipeline/gnss_data_support.hpp"

namespace pednav::pipeline {
namespace {

using namespace pednav::io;

using ::testing::HasSubstr;
using test::shared_data;
using namespace gnss_data;

// Issue 3 thresholds.
constexpr double kGalwayMinSolvedPct = 99.5;
constexpr double kGalway2dRms_m = 2.0;
constexpr double kGalway2dP95_m = 3.2;
constexpr double kGalway2dMax_m = 8.0;
constexpr double kSpirent2dRms_m = 0.05;
constexpr double kSeptentrioVelRms_mps = 0.05;
// Issue target 0.36 m (RTKLIB DGPS); measured 0.295 m with the default 10 s Doppler smoothing (0.375 m without).
constexpr double kSeptentrio2dRms_m = 0.36;
// Figures measured 2026-12-05 (Release; `pednav gnss` is deterministic), checked beside the issue's thresholds with
// +20 % (+30 % for Spirent's centimetre figures): a change of the solver (weights, exclusion, smoothing) that stays
// inside issue 3's thresholds still shows. Horizontal RMS / p95 / max [m].
constexpr double kMargin = 1.2;
constexpr Measured2d kGalwayG{1.356, 2.690, 4.234};
constexpr Measured2d kGalwayGlw1{1.754, 2.534, 4.104};
constexpr double kSpirentRms_m = 0.0122, kSpirentMax_m = 0.0162, kSpirentMargin = 1.3;
constexpr double kSeptentrioRms_m = 0.2946, kSeptentrioVelRms_m = 0.0273;

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

}  // namespace
}  // namespace pednav::pipeline
