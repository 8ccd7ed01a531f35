// SPDX-License-Identifier: BSD-2-Clause
// Broadcast satellite states on synthetic ephemerides: orbit radius, velocity and clock drift against
// central differences of the position/clock functions, ephemeris selection messages.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/geodesy.hpp"
#include "gnss/ephemeris.hpp"

namespace pednav::gnss {
namespace {

using ::testing::HasSubstr;

constexpr double kTolVelocity_mps = 1e-4;     // analytic vs central difference (h = 0.5 s)
constexpr double kTolDrift_sps = 1e-15;
constexpr double kDiffStep_s = 0.5;

KeplerEphemeris gps_like(System sys, int prn) {
  KeplerEphemeris k;
  k.sat = SatId{sys, prn};
  k.toe = GpsTime::from_week_tow(2022, 345600.0);
  k.toc = k.toe;
  k.toe_s = 345600.0;
  k.sqrt_a = 5153.6;
  k.e = 0.012;
  k.i0 = 0.96;
  k.omega0 = -1.2;
  k.omega = 0.7;
  k.m0 = 2.1;
  k.delta_n = 4.5e-9;
  k.omega_dot = -8.0e-9;
  k.idot = 2.0e-10;
  k.crc = 250.0;
  k.crs = -40.0;
  k.cuc = -2.0e-6;
  k.cus = 8.0e-6;
  k.cic = 1.0e-7;
  k.cis = -6.0e-8;
  k.af0 = 1.0e-4;
  k.af1 = -3.0e-12;
  k.af2 = 1.0e-19;
  return k;
}

void expect_derivatives_consistent(const std::function<SatState(GpsTime)>& f, GpsTime t) {
  const SatState s = f(t);
  const SatState sp = f(t.plus_s(kDiffStep_s)), sm = f(t.plus_s(-kDiffStep_s));
  const Eigen::Vector3d v_num = (sp.p_es_e - sm.p_es_e) / (2.0 * kDiffStep_s);
  EXPECT_LT((s.v_es_e - v_num).norm(), kTolVelocity_mps) << s.v_es_e.transpose() << " vs " << v_num.transpose();
  EXPECT_NEAR(s.clock_drift_sps, (sp.clock_bias_s - sm.clock_bias_s) / (2.0 * kDiffStep_s), kTolDrift_sps);
}

TEST(Ephemeris, KeplerVelocityAndDriftMatchNumericalDerivative) {
  for (System sys : {System::kGps, System::kGalileo, System::kQzss, System::kBeidou}) {
    KeplerEphemeris k = gps_like(sys, 7);
    for (double dt : {-7000.0, -100.0, 0.0, 3600.0, 7100.0}) {
      const GpsTime t = k.toe.plus_s(dt);
      const SatState s = kepler_satellite_state(k, t);
      EXPECT_GT(s.p_es_e.norm(), 2.5e7);
      EXPECT_LT(s.p_es_e.norm(), 2.8e7);
      expect_derivatives_consistent([&](GpsTime tt) { return kepler_satellite_state(k, tt); }, t);
    }
  }
}

TEST(Ephemeris, BeidouGeoCoRotatesAndVelocityMatches) {
  KeplerEphemeris k = gps_like(System::kBeidou, 3);
  k.beidou_geo = true;
  k.sqrt_a = 6493.4;  // geostationary radius 42164 km
  k.e = 0.0003;
  k.i0 = 5.0 * kDegToRad;  // broadcast GEO elements carry the +5 deg that the ICD rotation removes
  k.omega_dot = -3.0e-9;
  for (double dt : {-3000.0, 0.0, 2500.0}) {
    const GpsTime t = k.toe.plus_s(dt);
    const SatState s = kepler_satellite_state(k, t);
    EXPECT_NEAR(s.p_es_e.norm(), 4.2164e7, 2e4);
    EXPECT_LT(s.v_es_e.norm(), 1000.0);  // far below the 3 km/s of an MEO: the orbit turns with the Earth
    expect_derivatives_consistent([&](GpsTime tt) { return kepler_satellite_state(k, tt); }, t);
  }
}

TEST(Ephemeris, GlonassVelocityIsTheIntegratedState) {
  GlonassEphemeris g;
  g.sat = SatId{System::kGlonass, 4};
  g.toe = GpsTime::from_week_tow(2022, 345600.0);
  g.p_e = Eigen::Vector3d(1.2e7, -1.5e7, 1.6e7);
  // Circular-ish orbit velocity for r = 25.5e6 m, roughly perpendicular to p.
  const Eigen::Vector3d dir = g.p_e.cross(Eigen::Vector3d(0.3, 0.2, 1.0)).normalized();
  g.v_e = dir * std::sqrt(3.986e14 / g.p_e.norm());
  g.a_e = Eigen::Vector3d(1e-6, -2e-6, 3e-6);
  g.tau_n_s = 2e-5;
  g.gamma_n = 1e-12;
  for (double dt : {-900.0, -30.0, 0.0, 45.0, 1700.0}) {
    const GpsTime t = g.toe.plus_s(dt);
    expect_derivatives_consistent([&](GpsTime tt) { return glonass_satellite_state(g, tt); }, t);
    EXPECT_NEAR(glonass_satellite_state(g, t).clock_bias_s, -2e-5 + 1e-12 * dt, 1e-18);
  }
  EXPECT_LT((glonass_satellite_state(g, g.toe).p_es_e - g.p_e).norm(), 1e-9);
}

TEST(Ephemeris, SelectionPicksNearestHealthyAndExplainsFailures) {
  NavData nav;
  KeplerEphemeris a = gps_like(System::kGps, 5), b = gps_like(System::kGps, 5);
  b.toe = a.toe.plus_s(7200.0);
  b.toc = b.toe;
  b.toe_s = a.toe_s + 7200.0;
  b.iode = 9;
  nav.kepler = {a, b};
  auto s = satellite_state(nav, SatId{System::kGps, 5}, a.toe.plus_s(5000.0));
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->iode, 9);
  auto none = satellite_state(nav, SatId{System::kGps, 6}, a.toe);
  ASSERT_FALSE(none);
  EXPECT_THAT(none.error().message, HasSubstr("G06: no broadcast ephemeris"));
  auto old = satellite_state(nav, SatId{System::kGps, 5}, a.toe.plus_s(86400.0));
  ASSERT_FALSE(old);
  EXPECT_THAT(old.error().message, HasSubstr("G05: no ephemeris within"));
  nav.kepler[0].sv_health = 1;
  nav.kepler[1].sv_health = 1;
  auto sick = satellite_state(nav, SatId{System::kGps, 5}, a.toe);
  ASSERT_FALSE(sick);
  EXPECT_THAT(sick.error().message, HasSubstr("unhealthy"));
}

}  // namespace
}  // namespace pednav::gnss
