// SPDX-License-Identifier: BSD-2-Clause
// pednav broadcast satellite positions and clocks against RTKLIB's eph2pos/geph2pos on real nav files
// (GPS, GLONASS, Galileo, BeiDou incl. GEO, QZSS), every ephemeris at several times within its validity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gnss/ephemeris.hpp"
#include "gnss/rtklib/reference.hpp"
#include "gnss/rtklib/rinex.hpp"
#include "tests/support/data.hpp"

namespace pednav::gnss {
namespace {

constexpr double kTolPosition_m = 0.01;     // issue 3: < 1 cm against RTKLIB
constexpr double kTolClock_s = 1e-12;        // 0.3 mm
constexpr double kTolGloPosition_m = 0.01;

// Measured 2026-12-05 (Release), worst differences from RTKLIB over the three files: Kepler 3.96e-8 m, GLONASS
// 3.7e-9 m, clock 1.1e-22 s. These are round-off (1.5e-15 of the orbit radius), whose size depends on the operation
// order of each compiler: the bounds 1e-7 m / 1e-8 m / 1e-20 s are 2.5-100× the figures for that reason, and still
// 1e5 times below issue 3's 1 cm, so a model difference (a missed term, another Kepler tolerance) shows.
constexpr double kKeplerWorst_m = 1e-7, kGlonassWorst_m = 1e-8, kClockWorst_s = 1e-20;

// Compares every ephemeris of the file at several times; n_kepler / n_glonass: the file's ephemeris counts.
void compare_nav(const std::string& path, int n_kepler_expected, int n_glonass_expected) {
  auto nav = read_rinex_nav({path});
  ASSERT_TRUE(nav) << nav.error().message;
  int n_kepler = 0, n_glonass = 0;
  double worst_m = 0.0, worst_glo_m = 0.0, worst_clock_s = 0.0;
  for (const auto& k : nav->kepler) {
    for (double dt : {-3600.0, -60.0, 0.0, 1234.5, 3600.0}) {
      const GpsTime t = k.toe.plus_s(dt);
      const SatState s = kepler_satellite_state(k, t);
      Eigen::Vector3d p_ref;
      double dts_ref = 0.0;
      rtklib_reference::kepler_position(k, t, p_ref, dts_ref);
      worst_m = std::max(worst_m, (s.p_es_e - p_ref).norm());
      worst_clock_s = std::max(worst_clock_s, std::abs(s.clock_bias_s - dts_ref));
      EXPECT_LT((s.p_es_e - p_ref).norm(), kTolPosition_m) << k.sat.to_string() << " dt " << dt;
      EXPECT_NEAR(s.clock_bias_s, dts_ref, kTolClock_s) << k.sat.to_string();
    }
    ++n_kepler;
  }
  for (const auto& g : nav->glonass) {
    for (double dt : {-900.0, -30.0, 0.0, 61.0, 900.0}) {
      const GpsTime t = g.toe.plus_s(dt);
      const SatState s = glonass_satellite_state(g, t);
      Eigen::Vector3d p_ref;
      double dts_ref = 0.0;
      rtklib_reference::glonass_position(g, t, p_ref, dts_ref);
      worst_glo_m = std::max(worst_glo_m, (s.p_es_e - p_ref).norm());
      worst_clock_s = std::max(worst_clock_s, std::abs(s.clock_bias_s - dts_ref));
      EXPECT_LT((s.p_es_e - p_ref).norm(), kTolGloPosition_m) << g.sat.to_string() << " dt " << dt;
      EXPECT_NEAR(s.clock_bias_s, dts_ref, kTolClock_s);
    }
    ++n_glonass;
  }
  std::printf("[ephemeris] %s: %d Kepler, %d GLONASS; worst |dp| %.3e m (Kepler), %.3e m (GLONASS), |dt| %.3e s\n",
              path.substr(path.rfind('/') + 1).c_str(), n_kepler, n_glonass, worst_m, worst_glo_m, worst_clock_s);
  EXPECT_EQ(n_kepler, n_kepler_expected);
  EXPECT_EQ(n_glonass, n_glonass_expected);
  EXPECT_LT(worst_m, kKeplerWorst_m);
  EXPECT_LT(worst_glo_m, kGlonassWorst_m);
  EXPECT_LT(worst_clock_s, kClockWorst_s);
  ::testing::Test::RecordProperty("worst_kepler_m", std::to_string(worst_m));
}

TEST(EphemerisVsRtklib, GalwayGpsGlonass) {
  const std::string p = test::shared_data("gnss_ublox_m8p_walk_galway/rinex/base-20181004-1452.nav");
  PEDNAV_REQUIRE_DATA(p);
  compare_nav(p, 17, 31);
}

TEST(EphemerisVsRtklib, SeptentrioMixedIncludingBeidouGeo) {
  const std::string p = test::shared_data("gnss_septentrio_static_shortbaseline/base.nav");
  PEDNAV_REQUIRE_DATA(p);
  auto nav = read_rinex_nav({p});
  ASSERT_TRUE(nav) << nav.error().message;
  int geo = 0, gal = 0, qzs = 0;
  for (const auto& k : nav->kepler) {
    geo += k.beidou_geo;
    gal += k.sat.system == System::kGalileo;
    qzs += k.sat.system == System::kQzss;
  }
  EXPECT_GT(geo, 0);
  EXPECT_GT(gal, 0);
  EXPECT_GT(qzs, 0);
  compare_nav(p, 109, 19);
}

TEST(EphemerisVsRtklib, SpirentGalileo) {
  const std::string p = test::shared_data("rtklib_samples/instinct_spirent_rtk_GE/RINEX_EN_Spirent.23L");
  PEDNAV_REQUIRE_DATA(p);
  compare_nav(p, 26, 0);
}

}  // namespace
}  // namespace pednav::gnss
