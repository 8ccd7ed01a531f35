// SPDX-License-Identifier: BSD-2-Clause
// Broadcast-ephemeris satellite states. Equations: IS-GPS-200N Table 20-IV (position, clock, relativistic
// term), its velocity derivative (Remondi 2004, "Computing satellite velocity using the broadcast ephemeris"),
// BDS-SIS-ICD 2.0 §5.2.4.12 (GEO), GLONASS ICD 5.1 Appendix J.1 (state-vector integration).
#include "gnss/ephemeris.hpp"

#include <cmath>
#include <limits>

#include "core/geodesy.hpp"

namespace pednav::gnss {
namespace {

constexpr int kKeplerMaxIterations = 30;
constexpr double kKeplerTolerance_rad = 1e-14;
constexpr double kGlonassStep_s = 60.0;  // RK4 step, GLONASS ICD Appendix J.1 recommends <= 60 s
// GLONASS PZ-90 constants (ICD 5.1 Table 3.2).
constexpr double kGloGM_m3ps2 = 3.9860044e14;
constexpr double kGloJ2 = 1.0826257e-3;
constexpr double kGloAe_m = 6378136.0;
constexpr double kGloOmega_radps = 7.292115e-5;
// F = -2 sqrt(mu) / c^2 multiplies e sqrt(A) sin(E) (IS-GPS-200 20.3.3.3.3.1).
double relativity_factor(double gm) { return -2.0 * std::sqrt(gm) / (kSpeedOfLight_mps * kSpeedOfLight_mps); }

using Vector6d = Eigen::Matrix<double, 6, 1>;

// PZ-90 equations of motion in the rotating frame with J2 and the broadcast luni-solar acceleration
// (ICD 5.1 eq. J.1): state [x y z vx vy vz].
Vector6d glonass_derivative(const Vector6d& x, const Eigen::Vector3d& a_ls_e) {
  const double r2 = x.head<3>().squaredNorm();
  const double r = std::sqrt(r2);
  const double r3 = r2 * r;
  const double j2_term = 1.5 * kGloJ2 * kGloGM_m3ps2 * kGloAe_m * kGloAe_m / (r2 * r3);
  const double z2_r2 = 5.0 * x(2) * x(2) / r2;
  const double c = -kGloGM_m3ps2 / r3 - j2_term * (1.0 - z2_r2);
  const double w2 = kGloOmega_radps * kGloOmega_radps;
  Vector6d d;
  d.head<3>() = x.tail<3>();
  d(3) = (c + w2) * x(0) + 2.0 * kGloOmega_radps * x(4) + a_ls_e(0);
  d(4) = (c + w2) * x(1) - 2.0 * kGloOmega_radps * x(3) + a_ls_e(1);
  d(5) = (c - 2.0 * j2_term) * x(2) + a_ls_e(2);
  return d;
}

}  // namespace

OrbitConstants orbit_constants(System system) {
  switch (system) {
    case System::kGalileo: return {3.986004418e14, 7.2921151467e-5};
    case System::kBeidou: return {3.986004418e14, 7.2921150e-5};
    case System::kGlonass: return {kGloGM_m3ps2, kGloOmega_radps};
    default: return {3.9860050e14, 7.2921151467e-5};  // GPS, QZSS (IS-GPS-200, IS-QZSS)
  }
}

double max_ephemeris_age_s(System system) {
  switch (system) {
    case System::kGlonass: return 1800.0;   // toe every 30 min
    case System::kGalileo: return 14400.0;  // I/NAV updated every 10 min, valid 4 h
    case System::kBeidou: return 21600.0;
    default: return 7200.0 + 60.0;          // GPS/QZSS: 4 h fit interval centred on toe (+ slack for odd toe)
  }
}

SatState kepler_satellite_state(const KeplerEphemeris& eph, GpsTime t) {
  const OrbitConstants k = orbit_constants(eph.sat.system);
  const double a = eph.sqrt_a * eph.sqrt_a;
  const double tk = t - eph.toe;
  const double n = std::sqrt(k.gm_m3ps2 / (a * a * a)) + eph.delta_n;  // corrected mean motion
  const double m = eph.m0 + n * tk;
  // Kepler's equation M = E - e sin E by Newton iteration.
  double e_anom = m;
  for (int i = 0; i < kKeplerMaxIterations; ++i) {
    const double step = (e_anom - eph.e * std::sin(e_anom) - m) / (1.0 - eph.e * std::cos(e_anom));
    e_anom -= step;
    if (std::abs(step) < kKeplerTolerance_rad) break;
  }
  const double sin_e = std::sin(e_anom), cos_e = std::cos(e_anom);
  const double one_minus_ecos = 1.0 - eph.e * cos_e;
  const double sqrt_1me2 = std::sqrt(1.0 - eph.e * eph.e);
  const double nu = std::atan2(sqrt_1me2 * sin_e, cos_e - eph.e);
  const double phi = nu + eph.omega;  // argument of latitude
  const double sin2p = std::sin(2.0 * phi), cos2p = std::cos(2.0 * phi);
  const double u = phi + eph.cus * sin2p + eph.cuc * cos2p;
  const double r = a * one_minus_ecos + eph.crs * sin2p + eph.crc * cos2p;
  const double inc = eph.i0 + eph.idot * tk + eph.cis * sin2p + eph.cic * cos2p;
  // Time derivatives (Remondi 2004).
  const double e_dot = n / one_minus_ecos;
  const double nu_dot = e_dot * sqrt_1me2 / one_minus_ecos;
  const double u_dot = nu_dot * (1.0 + 2.0 * (eph.cus * cos2p - eph.cuc * sin2p));
  const double r_dot = a * eph.e * sin_e * e_dot + 2.0 * (eph.crs * cos2p - eph.crc * sin2p) * nu_dot;
  const double inc_dot = eph.idot + 2.0 * (eph.cis * cos2p - eph.cic * sin2p) * nu_dot;
  // Position and velocity in the orbital plane.
  const double cu = std::cos(u), su = std::sin(u);
  const double xp = r * cu, yp = r * su;
  const double xp_dot = r_dot * cu - r * su * u_dot;
  const double yp_dot = r_dot * su + r * cu * u_dot;
  const double ci = std::cos(inc), si = std::sin(inc);

  SatState s;
  s.iode = eph.iode;
  s.group_delay_s = eph.tgd_s;
  if (eph.sat.system == System::kBeidou && eph.beidou_geo) {
    // GEO: node in the inertial-like frame of toe, then rotate by Rz(omega_e tk) Rx(-5 deg) (BDS ICD 5.2.4.12).
    const double big_omega = eph.omega0 + eph.omega_dot * tk - k.omega_ie_radps * eph.toe_s;
    const double co = std::cos(big_omega), so = std::sin(big_omega);
    const Eigen::Vector3d p_g(xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si);
    const Eigen::Vector3d v_g(xp_dot * co - yp_dot * ci * so + yp * si * so * inc_dot - p_g.y() * eph.omega_dot,
                              xp_dot * so + yp_dot * ci * co - yp * si * co * inc_dot + p_g.x() * eph.omega_dot,
                              yp_dot * si + yp * ci * inc_dot);
    const double c5 = std::cos(-5.0 * kDegToRad), s5 = std::sin(-5.0 * kDegToRad);
    Eigen::Matrix3d rx;
    rx << 1, 0, 0, 0, c5, s5, 0, -s5, c5;
    const double ang = k.omega_ie_radps * tk, ca = std::cos(ang), sa = std::sin(ang);
    Eigen::Matrix3d rz, rz_dot;
    rz << ca, sa, 0, -sa, ca, 0, 0, 0, 1;
    rz_dot << -sa, ca, 0, -ca, -sa, 0, 0, 0, 0;
    rz_dot *= k.omega_ie_radps;
    s.p_es_e = rz * rx * p_g;
    s.v_es_e = rz_dot * rx * p_g + rz * rx * v_g;
  } else {
    // Longitude of the ascending node in ECEF (IS-GPS-200 Table 20-IV).
    const double big_omega = eph.omega0 + (eph.omega_dot - k.omega_ie_radps) * tk - k.omega_ie_radps * eph.toe_s;
    const double big_omega_dot = eph.omega_dot - k.omega_ie_radps;
    const double co = std::cos(big_omega), so = std::sin(big_omega);
    s.p_es_e = Eigen::Vector3d(xp * co - yp * ci * so, xp * so + yp * ci * co, yp * si);
    s.v_es_e = Eigen::Vector3d(
        xp_dot * co - yp_dot * ci * so + yp * si * so * inc_dot - s.p_es_e.y() * big_omega_dot,
        xp_dot * so + yp_dot * ci * co - yp * si * co * inc_dot + s.p_es_e.x() * big_omega_dot,
        yp_dot * si + yp * ci * inc_dot);
  }
  // Clock polynomial at toc + relativistic correction dtr = F e sqrt(A) sin E (IS-GPS-200 20.3.3.3.3.1).
  const double tc = t - eph.toc;
  const double f = relativity_factor(k.gm_m3ps2);
  s.clock_bias_s = eph.af0 + eph.af1 * tc + eph.af2 * tc * tc + f * eph.e * eph.sqrt_a * sin_e;
  s.clock_drift_sps = eph.af1 + 2.0 * eph.af2 * tc + f * eph.e * eph.sqrt_a * cos_e * e_dot;
  return s;
}

SatState glonass_satellite_state(const GlonassEphemeris& eph, GpsTime t) {
  double dt = t - eph.toe;
  Vector6d x;
  x << eph.p_e, eph.v_e;
  // RK4 from toe to t in steps of at most 60 s (ICD 5.1 J.1); the luni-solar term is held constant.
  double h = dt < 0.0 ? -kGlonassStep_s : kGlonassStep_s;
  while (std::abs(dt) > 1e-9) {
    if (std::abs(dt) < kGlonassStep_s) h = dt;
    const Vector6d k1 = glonass_derivative(x, eph.a_e);
    const Vector6d k2 = glonass_derivative(x + 0.5 * h * k1, eph.a_e);
    const Vector6d k3 = glonass_derivative(x + 0.5 * h * k2, eph.a_e);
    const Vector6d k4 = glonass_derivative(x + h * k3, eph.a_e);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    dt -= h;
  }
  SatState s;
  s.p_es_e = x.head<3>();
  s.v_es_e = x.tail<3>();
  const double tc = t - eph.toe;
  s.clock_bias_s = -eph.tau_n_s + eph.gamma_n * tc;  // ICD 5.1 eq. 3.3.3
  s.clock_drift_sps = eph.gamma_n;
  s.iode = eph.iode;
  return s;
}

Expected<SatState> satellite_state(const NavData& nav, SatId sat, GpsTime t) {
  const double max_age_s = max_ephemeris_age_s(sat.system);
  bool any = false, any_healthy = false;
  if (sat.system == System::kGlonass) {
    const GlonassEphemeris* best = nullptr;
    double best_age = std::numeric_limits<double>::infinity();
    for (const auto& g : nav.glonass) {
      if (g.sat != sat) continue;
      any = true;
      if (g.sv_health != 0) continue;
      any_healthy = true;
      const double age = std::abs(t - g.toe);
      if (age <= max_age_s && age < best_age) best = &g, best_age = age;
    }
    if (best) return glonass_satellite_state(*best, t);
  } else {
    const KeplerEphemeris* best = nullptr;
    double best_age = std::numeric_limits<double>::infinity();
    for (const auto& k : nav.kepler) {
      if (k.sat != sat) continue;
      any = true;
      if (k.sv_health != 0) continue;
      any_healthy = true;
      const double age = std::abs(t - k.toe);
      if (age <= max_age_s && age < best_age) best = &k, best_age = age;
    }
    if (best) return kepler_satellite_state(*best, t);
  }
  if (!any) return make_error(sat.to_string() + ": no broadcast ephemeris");
  if (!any_healthy) return make_error(sat.to_string() + ": ephemeris flagged unhealthy");
  return make_error(sat.to_string() + ": no ephemeris within " + std::to_string(static_cast<int>(max_age_s)) +
                    " s of " + t.to_string());
}

}  // namespace pednav::gnss
