// SPDX-License-Identifier: BSD-2-Clause
// The RTKLIB adapter on real RINEX 2.10 and 3.04 files from ../shared/datasets.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>

#include "gnss/rtklib/rinex.hpp"
#include "tests/support/data.hpp"

namespace pednav::gnss {
namespace {

using ::testing::HasSubstr;
using test::shared_data;

TEST(RinexAdapter, Rinex210GeonetRover) {
  const std::string path = shared_data("rtklib_samples/rtklib_b34_geonet_gps/07590920.05o");
  PEDNAV_REQUIRE_DATA(path);
  auto obs = read_rinex_obs(path, SystemSelection{});
  ASSERT_TRUE(obs) << obs.error().message;
  // SOURCE.md: 2005-04-02 00:00:00 .. 00:59:30 GPST, 30 s, 120 epochs, GPS only, no Doppler/SNR.
  ASSERT_EQ(obs->epochs.size(), 120u);
  EXPECT_EQ(obs->epochs.front().time, GpsTime::from_calendar_gpst({2005, 4, 2, 0, 0, 0.0}));
  // Epoch tags carry the receiver's millisecond clock steering (0:59:30.005).
  EXPECT_EQ(obs->epochs.back().time, GpsTime::from_calendar_gpst({2005, 4, 2, 0, 59, 30.005}));
  EXPECT_NEAR(obs->approx_position_e.x(), -3976219.5082, 1e-3);
  std::set<int> prns;
  for (const auto& e : obs->epochs) {
    EXPECT_GE(e.sats.size(), 5u);
    for (const auto& s : e.sats) {
      prns.insert(s.sat.prn);
      EXPECT_TRUE(std::isnan(s.doppler_hz));
      EXPECT_GT(s.pseudorange_m, 1.9e7);
      EXPECT_LT(s.pseudorange_m, 2.7e7);
    }
  }
  EXPECT_EQ(prns.size(), 11u);  // measured 2026-12-05 (a property of the file)
}

TEST(RinexAdapter, Rinex304GalwayRoverWithDopplerAndCn0) {
  const std::string path = shared_data("gnss_ublox_m8p_walk_galway/rinex/rover-20181004-1532.obs");
  PEDNAV_REQUIRE_DATA(path);
  SystemSelection sel;
  sel.glonass = true;
  auto obs = read_rinex_obs(path, sel);
  ASSERT_TRUE(obs) << obs.error().message;
  // SOURCE.md: 1180 obs epochs 15:33:40.987 - 15:53:19.987 GPST (event records are not epochs).
  EXPECT_EQ(obs->epochs.size(), 1180u);
  EXPECT_EQ(obs->epochs.front().time, GpsTime::from_calendar_gpst({2018, 10, 4, 15, 33, 40.987}));
  EXPECT_EQ(obs->epochs.back().time, GpsTime::from_calendar_gpst({2018, 10, 4, 15, 53, 19.987}));
  int gps = 0, glo = 0, with_doppler = 0, with_cn0 = 0;
  for (const auto& e : obs->epochs) {
    for (const auto& s : e.sats) {
      (s.sat.system == System::kGps ? gps : glo)++;
      with_doppler += !std::isnan(s.doppler_hz);
      with_cn0 += !std::isnan(s.cn0_dbhz);
      if (!std::isnan(s.cn0_dbhz)) {
        EXPECT_GT(s.cn0_dbhz, 5.0);
        EXPECT_LT(s.cn0_dbhz, 60.0);
      }
      if (s.sat.system == System::kGlonass) {
        EXPECT_GT(s.wavelength_m, 0.185);  // G1 channels -7..6: 0.1863 .. 0.1875 m
        EXPECT_LT(s.wavelength_m, 0.188);
      }
    }
  }
  // Measured 2026-12-05 (properties of the file: exact): 10805 GPS and 11154 GLONASS observations, every one with
  // Doppler and C/N0.
  EXPECT_EQ(gps, 10805);
  EXPECT_EQ(glo, 11154);
  EXPECT_EQ(with_doppler, gps + glo);
  EXPECT_EQ(with_cn0, gps + glo);
}

TEST(RinexAdapter, NavFilesMerge) {
  const std::string a = shared_data("gnss_ublox_m8p_walk_galway/rinex/base-20181004-1452.nav");
  const std::string b = shared_data("gnss_ublox_m8p_walk_galway/cors_glw1/glw1277p.18n");
  PEDNAV_REQUIRE_DATA(a);
  PEDNAV_REQUIRE_DATA(b);
  auto nav = read_rinex_nav({a, b});
  ASSERT_TRUE(nav) << nav.error().message;
  std::set<int> gps;
  for (const auto& k : nav->kepler) {
    if (k.sat.system == System::kGps) gps.insert(k.sat.prn);
    EXPECT_GT(k.sqrt_a, 5000.0);
  }
  EXPECT_EQ(gps.size(), 31u);             // measured 2026-12-05 (properties of the files: exact)
  EXPECT_EQ(nav->glonass.size(), 31u);
}

TEST(RinexAdapter, BadInputsNameTheFile) {
  auto missing = read_rinex_obs("/nonexistent/rover.obs", SystemSelection{});
  ASSERT_FALSE(missing);
  EXPECT_THAT(missing.error().message, HasSubstr("/nonexistent/rover.obs: file not found"));
  const std::string empty_path = ::testing::TempDir() + "pednav_empty.obs";
  { std::ofstream(empty_path).close(); }
  auto empty = read_rinex_obs(empty_path, SystemSelection{});
  ASSERT_FALSE(empty);
  EXPECT_THAT(empty.error().message, HasSubstr("pednav_empty.obs: file is empty"));
  const std::string junk_path = ::testing::TempDir() + "pednav_junk.obs";
  { std::ofstream(junk_path) << "this is not rinex\n"; }
  auto junk = read_rinex_obs(junk_path, SystemSelection{});
  ASSERT_FALSE(junk);
  EXPECT_THAT(junk.error().message, HasSubstr("no RINEX observation epochs"));
  auto nav = read_rinex_nav({junk_path});
  ASSERT_FALSE(nav);
  EXPECT_THAT(nav.error().message, HasSubstr("no broadcast ephemeris"));
}

}  // namespace
}  // namespace pednav::gnss
