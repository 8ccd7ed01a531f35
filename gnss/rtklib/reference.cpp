// SPDX-License-Identifier: BSD-2-Clause
// Test oracle: pednav ephemeris types converted back to RTKLIB's eph_t/geph_t and evaluated by RTKLIB.
#include "gnss/rtklib/reference.hpp"

#include "gnss/rtklib/rtklib_c.hpp"

namespace pednav::gnss::rtklib_reference {
namespace {

constexpr int64_t kGpsEpochUnix_s = 315964800;  // 1980-01-06 in gtime_t's Unix-like count

gtime_t to_gtime(GpsTime t) {
  gtime_t g{};
  const int64_t ns = t.ns();
  int64_t whole = ns / kNsPerS;
  int64_t frac = ns % kNsPerS;
  if (frac < 0) frac += kNsPerS, --whole;
  g.time = static_cast<time_t>(whole + kGpsEpochUnix_s);
  g.sec = static_cast<double>(frac) * 1e-9;
  return g;
}

int rtk_system(System s) {
  switch (s) {
    case System::kGlonass: return SYS_GLO;
    case System::kGalileo: return SYS_GAL;
    case System::kBeidou: return SYS_CMP;
    case System::kQzss: return SYS_QZS;
    default: return SYS_GPS;
  }
}

}  // namespace

void kepler_position(const KeplerEphemeris& k, GpsTime t, Eigen::Vector3d& p_es_e, double& clock_bias_s) {
  eph_t e{};
  e.sat = satno(rtk_system(k.sat.system), k.sat.prn);
  e.iode = k.iode;
  e.toe = to_gtime(k.toe);
  e.toc = to_gtime(k.toc);
  e.A = k.sqrt_a * k.sqrt_a;
  e.e = k.e;
  e.i0 = k.i0;
  e.OMG0 = k.omega0;
  e.omg = k.omega;
  e.M0 = k.m0;
  e.deln = k.delta_n;
  e.OMGd = k.omega_dot;
  e.idot = k.idot;
  e.crc = k.crc;
  e.crs = k.crs;
  e.cuc = k.cuc;
  e.cus = k.cus;
  e.cic = k.cic;
  e.cis = k.cis;
  e.toes = k.toe_s;
  e.f0 = k.af0;
  e.f1 = k.af1;
  e.f2 = k.af2;
  double rs[3] = {0, 0, 0}, dts = 0.0, var = 0.0;
  eph2pos(to_gtime(t), &e, rs, &dts, &var);
  p_es_e = Eigen::Vector3d(rs[0], rs[1], rs[2]);
  clock_bias_s = dts;
}

void glonass_position(const GlonassEphemeris& g, GpsTime t, Eigen::Vector3d& p_es_e, double& clock_bias_s) {
  geph_t e{};
  e.sat = satno(SYS_GLO, g.sat.prn);
  e.toe = to_gtime(g.toe);
  e.tof = to_gtime(g.tof);
  for (int i = 0; i < 3; ++i) {
    e.pos[i] = g.p_e(i);
    e.vel[i] = g.v_e(i);
    e.acc[i] = g.a_e(i);
  }
  e.taun = g.tau_n_s;
  e.gamn = g.gamma_n;
  double rs[3] = {0, 0, 0}, dts = 0.0, var = 0.0;
  geph2pos(to_gtime(t), &e, rs, &dts, &var);
  p_es_e = Eigen::Vector3d(rs[0], rs[1], rs[2]);
  clock_bias_s = dts;
}

double klobuchar_delay_m(const std::array<double, 8>& alpha_beta, GpsTime t, const Geodetic& llh, double azimuth_rad,
                         double elevation_rad) {
  const double pos[3] = {llh.lat, llh.lon, llh.h_m};  // ionmodel: {lat, lon [rad], h [m]}
  const double azel[2] = {azimuth_rad, elevation_rad};  // ionmodel: {az, el} [rad]
  return ionmodel(to_gtime(t), alpha_beta.data(), pos, azel);
}

}  // namespace pednav::gnss::rtklib_reference
