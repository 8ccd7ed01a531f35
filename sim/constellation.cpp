// SPDX-License-Identifier: BSD-2-Clause
// Nominal GPS constellation (docs/sim.md §5). Slot table: SPS Performance Standard (2008) Table 3.1-1
// (RAAN of planes A-F and argument of latitude of the 24 baseline slots at the reference epoch), used here
// as relative geometry at the start of the scenario's GPS week.
#include "sim/constellation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/geodesy.hpp"
#include "sim/random.hpp"

namespace pednav::sim {
namespace {

constexpr double kPlaneRaan_deg[6] = {272.847, 332.847, 32.847, 92.847, 152.847, 212.847};
constexpr double kSlotArgLat_deg[6][4] = {{268.126, 161.786, 11.676, 41.806},  {80.956, 173.336, 309.976, 204.376},
                                          {111.876, 11.796, 339.666, 241.556}, {135.226, 265.446, 35.156, 167.356},
                                          {197.046, 302.596, 66.066, 333.686}, {238.886, 345.226, 105.206, 135.346}};
constexpr double kSemiMajorAxis_m = 26559.7e3;
constexpr double kOmegaDot_radps = -8.0e-9;  // typical broadcast node regression
constexpr double kGmGps = 3.986005e14;       // IS-GPS-200 mu
constexpr int64_t kToeSpacing_s = 7200;

struct Slot {
  double raan_rad, arg_lat_rad;
};

std::vector<Slot> slots(int n) {
  std::vector<std::vector<double>> planes(6);
  for (int p = 0; p < 6; ++p)
    for (int s = 0; s < 4; ++s) planes[static_cast<size_t>(p)].push_back(kSlotArgLat_deg[p][s]);
  for (int extra = 0; extra < n - 24; ++extra) {  // spares: widest gap of plane (extra mod 6)
    auto& pl = planes[static_cast<size_t>(extra % 6)];
    std::vector<double> v = pl;
    std::sort(v.begin(), v.end());
    double best_gap = -1.0, mid = 0.0;
    for (size_t i = 0; i < v.size(); ++i) {
      const double a = v[i], b = i + 1 < v.size() ? v[i + 1] : v.front() + 360.0;
      if (b - a > best_gap) {
        best_gap = b - a;
        mid = std::fmod(0.5 * (a + b), 360.0);
      }
    }
    pl.push_back(mid);
  }
  std::vector<Slot> out;
  for (size_t k = 0; out.size() < static_cast<size_t>(n); ++k)  // interleave planes so PRN order mixes them
    for (int p = 0; p < 6; ++p)
      if (k < planes[static_cast<size_t>(p)].size() && out.size() < static_cast<size_t>(n))
        out.push_back({kPlaneRaan_deg[p] * kDegToRad, planes[static_cast<size_t>(p)][k] * kDegToRad});
  return out;
}

double wrap_2pi_signed(double a) {
  a = std::fmod(a, 2.0 * kPi);
  if (a > kPi) a -= 2.0 * kPi;
  if (a <= -kPi) a += 2.0 * kPi;
  return a;
}

}  // namespace

double rinex_nav_round(double value) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12E", value);
  return std::strtod(buf, nullptr);
}

gnss::NavData nominal_gps_constellation(int satellites, GpsTime t_begin, GpsTime t_end, uint64_t seed) {
  Rng r(seed, kStreamConstellation);
  gnss::NavData nav;
  nav.klobuchar = {1.1176e-08, 7.4506e-09, -5.9605e-08, -5.9605e-08, 9.0112e+04, 4.9152e+04, -1.3107e+05, -3.2768e+05};
  nav.has_klobuchar = true;
  const int w0 = t_begin.week();
  const GpsTime week0 = GpsTime::from_week_tow(w0, 0.0);
  const double n_mean = std::sqrt(kGmGps / (kSemiMajorAxis_m * kSemiMajorAxis_m * kSemiMajorAxis_m));
  const double week_rotation = std::fmod(wgs84::kOmegaIE_radps * static_cast<double>(kSecondsPerWeek), 2.0 * kPi);
  const int64_t first = ((t_begin.ns() / kNsPerS - 2 * kToeSpacing_s) / kToeSpacing_s) * kToeSpacing_s;
  const int64_t last = t_end.ns() / kNsPerS + 2 * kToeSpacing_s;
  const auto sl = slots(satellites);
  for (size_t k = 0; k < sl.size(); ++k) {
    // Per-satellite constants of the orbit and clock (small eccentricity exercises the relativistic term).
    const double e = 0.002 + 0.010 * r.uniform();
    const double omega = r.uniform(-kPi, kPi);
    const double inc = (55.0 + 0.5 * r.normal()) * kDegToRad;
    const double af0 = 2.0e-4 * r.normal(), af1 = 2.0e-12 * r.normal();
    // At the week start: argument of latitude u0 = omega + true anomaly ~ omega + M (e small; exact M below).
    const double nu0 = sl[k].arg_lat_rad - omega;
    const double E0 = 2.0 * std::atan(std::sqrt((1.0 - e) / (1.0 + e)) * std::tan(0.5 * nu0));
    const double M_ref = E0 - e * std::sin(E0);
    for (int64_t toe_abs = first; toe_abs <= last; toe_abs += kToeSpacing_s) {
      gnss::KeplerEphemeris eph;
      eph.sat = {gnss::System::kGps, static_cast<int>(k) + 1};
      eph.toe = GpsTime::from_ns(toe_abs * kNsPerS);
      const double since_ref = eph.toe - week0;
      eph.week = eph.toe.week();
      eph.toe_s = rinex_nav_round(eph.toe.tow_s());
      eph.toc = eph.toe;
      eph.ttr = eph.toe.plus_ns(-60 * kNsPerS);
      eph.iode = static_cast<int>((toe_abs / kToeSpacing_s) % 256);
      eph.iodc = eph.iode;
      eph.sqrt_a = rinex_nav_round(std::sqrt(kSemiMajorAxis_m));
      eph.e = rinex_nav_round(e);
      eph.i0 = rinex_nav_round(inc);
      eph.omega = rinex_nav_round(omega);
      eph.omega_dot = rinex_nav_round(kOmegaDot_radps);
      eph.m0 = rinex_nav_round(wrap_2pi_signed(M_ref + n_mean * since_ref));
      eph.omega0 = rinex_nav_round(wrap_2pi_signed(sl[k].raan_rad + kOmegaDot_radps * since_ref -
                                                   static_cast<double>(eph.week - w0) * week_rotation));
      eph.fit_interval_h = 4.0;
      eph.af0 = rinex_nav_round(af0 + af1 * since_ref);
      eph.af1 = rinex_nav_round(af1);
      nav.kepler.push_back(eph);
    }
  }
  return nav;
}

}  // namespace pednav::sim
