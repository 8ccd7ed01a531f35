// SPDX-License-Identifier: BSD-2-Clause
#include <gtest/gtest.h>

#include <random>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"

namespace pednav {
namespace {

constexpr double kTolRoundTrip_m = 1e-6;

double round_trip_error_m(const Geodetic& g) {
  const Eigen::Vector3d p = ecef_from_geodetic(g);
  const Geodetic back = geodetic_from_ecef(p);
  return (ecef_from_geodetic(back) - p).norm() + std::abs(back.h_m - g.h_m);
}

TEST(Geodesy, RoundTripEverywhere) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> lat(-kPi / 2, kPi / 2), lon(-kPi, kPi), h(-1000.0, 100000.0);
  for (int i = 0; i < 20000; ++i) {
    const Geodetic g{lat(rng), lon(rng), h(rng)};
    ASSERT_LT(round_trip_error_m(g), kTolRoundTrip_m) << g.lat << " " << g.lon << " " << g.h_m;
  }
  for (double la : {-kPi / 2, -kPi / 2 + 1e-9, -1e-12, 0.0, 1e-12, kPi / 2 - 1e-9, kPi / 2}) {
    for (double hh : {-1000.0, 0.0, 100000.0}) {
      EXPECT_LT(round_trip_error_m({la, 0.3, hh}), kTolRoundTrip_m) << la << " " << hh;
    }
  }
}

TEST(Geodesy, KnownPoint) {
  // Septentrio base (SOURCE.md): 35.134707705 N, 136.977577939 E, 104.853 m -> ECEF given there.
  const Eigen::Vector3d p = ecef_from_geodetic({35.134707705 * kDegToRad, 136.977577939 * kDegToRad, 104.853});
  EXPECT_NEAR(p.x(), -3817681.1213, 2e-3);
  EXPECT_NEAR(p.y(), 3562839.4311, 2e-3);
  EXPECT_NEAR(p.z(), 3650159.1593, 2e-3);
  // Pole: z = b + h.
  const Geodetic pole = geodetic_from_ecef({0.0, 0.0, wgs84::kB_m + 10.0});
  EXPECT_NEAR(pole.lat, kPi / 2, 1e-12);
  EXPECT_NEAR(pole.h_m, 10.0, 1e-6);
}

TEST(Geodesy, NedFrameIsOrthonormalAndPointsTheRightWay) {
  const Geodetic g{0.9, -0.15, 50.0};
  const Eigen::Matrix3d r = R_e_n(g.lat, g.lon);
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
  // 1 m north raises latitude, 1 m down lowers height.
  const Eigen::Vector3d p0 = ecef_from_geodetic(g);
  const Geodetic north = geodetic_from_ecef(p0 + r.col(0));
  EXPECT_GT(north.lat, g.lat);
  EXPECT_NEAR(geodetic_from_ecef(p0 + r.col(2)).h_m, g.h_m - 1.0, 1e-6);
  const Eigen::Vector3d ned(3.0, -4.0, 1.5);
  EXPECT_LT((ned_from_ecef(ecef_from_ned(ned, p0), p0) - ned).norm(), 1e-9);
  const Eigen::Vector3d enu = enu_from_ecef(ecef_from_ned(ned, p0), p0);
  EXPECT_NEAR(enu.x(), -4.0, 1e-9);
  EXPECT_NEAR(enu.y(), 3.0, 1e-9);
  EXPECT_NEAR(enu.z(), -1.5, 1e-9);
}

TEST(Geodesy, RadiiOfCurvature) {
  double rn = 0, re = 0;
  radii_of_curvature(0.0, rn, re);
  EXPECT_NEAR(re, wgs84::kA_m, 1e-6);
  EXPECT_NEAR(rn, wgs84::kA_m * (1 - wgs84::kE2), 1e-6);
  radii_of_curvature(kPi / 2, rn, re);
  EXPECT_NEAR(rn, re, 1e-6);  // equal at the pole
}

}  // namespace
}  // namespace pednav
