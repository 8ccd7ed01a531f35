// SPDX-License-Identifier: BSD-2-Clause
// Measurement models: see gnss/measurement.hpp and docs/gnss.md ("Measurement models").
#include "gnss/measurement.hpp"

#include <algorithm>
#include <cmath>

namespace pednav::gnss {
namespace {
constexpr double kOmega = wgs84::kOmegaIE_radps;
constexpr double kC = kSpeedOfLight_mps;
constexpr int kClockIterations = 2;
}  // namespace

Expected<SatState> satellite_state_at_reception(const NavData& nav, SatId sat, GpsTime t_rx, double pseudorange_m) {
  // Signal travel time from the pseudorange; the satellite clock correction is refined once (|dt_s| < 1 ms,
  // drift < 1e-9, so the second pass changes the time by < 1 ps).
  GpsTime t_tx = t_rx.plus_s(-pseudorange_m / kC);
  Expected<SatState> s = satellite_state(nav, sat, t_tx);
  for (int i = 0; i < kClockIterations && s; ++i) {
    s = satellite_state(nav, sat, t_rx.plus_s(-pseudorange_m / kC - s->clock_bias_s));
  }
  return s;
}

LineOfSight line_of_sight(const SatState& sat, const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& v_ea_e) {
  LineOfSight l;
  const Eigen::Vector3d d = sat.p_es_e - p_ea_e;
  const double dist = d.norm();
  l.u_as_e = d / dist;
  // Sagnac term (Groves 2013 eq. 8.35 to first order): omega/c (x_s y_a - y_s x_a).
  const Eigen::Vector3d& ps = sat.p_es_e;
  const Eigen::Vector3d& vs = sat.v_es_e;
  l.range_m = dist + kOmega / kC * (ps.x() * p_ea_e.y() - ps.y() * p_ea_e.x());
  l.J_range_p = -l.u_as_e.transpose() + kOmega / kC * Eigen::RowVector3d(-ps.y(), ps.x(), 0.0);
  const Eigen::Vector3d dv = vs - v_ea_e;
  l.range_rate_mps = l.u_as_e.dot(dv) + kOmega / kC *
                     (vs.x() * p_ea_e.y() + ps.x() * v_ea_e.y() - vs.y() * p_ea_e.x() - ps.y() * v_ea_e.x());
  // d(u.dv)/dp_a = -dv^T (I - u u^T) / |d|.
  l.J_rate_p = -(dv - l.u_as_e * l.u_as_e.dot(dv)).transpose() / dist +
               kOmega / kC * Eigen::RowVector3d(-vs.y(), vs.x(), 0.0);
  l.J_rate_v = -l.u_as_e.transpose() + kOmega / kC * Eigen::RowVector3d(-ps.y(), ps.x(), 0.0);
  return l;
}

ElevationAzimuth elevation_azimuth(const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& p_es_e) {
  const Eigen::Vector3d enu = enu_from_ecef(p_es_e, p_ea_e);
  ElevationAzimuth ea;
  ea.elevation = std::atan2(enu.z(), std::hypot(enu.x(), enu.y()));
  ea.azimuth = std::atan2(enu.x(), enu.y());
  if (ea.azimuth < 0.0) ea.azimuth += 2.0 * kPi;
  return ea;
}

MeasurementRow ud_pseudorange(SatId sat, const SignalAtReceiver& s, const Eigen::Vector3d& p_ea_e, double clock_m,
                              double iono_m, double tropo_m) {
  const LineOfSight l = line_of_sight(s.sat, p_ea_e, Eigen::Vector3d::Zero());
  MeasurementRow r;
  r.sat = sat;
  const double predicted = l.range_m + clock_m - kC * (s.sat.clock_bias_s - s.sat.group_delay_s) + iono_m + tropo_m;
  r.residual = s.pseudorange_m - predicted;
  r.J_p = l.J_range_p;
  r.J_clock = 1.0;
  return r;
}

MeasurementRow ud_range_rate(SatId sat, const SignalAtReceiver& s, const Eigen::Vector3d& p_ea_e,
                             const Eigen::Vector3d& v_ea_e, double drift_mps) {
  const LineOfSight l = line_of_sight(s.sat, p_ea_e, v_ea_e);
  MeasurementRow r;
  r.sat = sat;
  r.residual = s.range_rate_mps - (l.range_rate_mps + drift_mps - kC * s.sat.clock_drift_sps);
  r.J_p = l.J_rate_p;
  r.J_v = l.J_rate_v;
  r.J_drift = 1.0;
  return r;
}

MeasurementRow sd_pseudorange(SatId sat, const SignalAtReceiver& rover, const SignalAtReceiver& base,
                              const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& p_eb_e, double clock_rb_m) {
  const LineOfSight lr = line_of_sight(rover.sat, p_ea_e, Eigen::Vector3d::Zero());
  const LineOfSight lb = line_of_sight(base.sat, p_eb_e, Eigen::Vector3d::Zero());
  MeasurementRow r;
  r.sat = sat;
  const double predicted =
      lr.range_m - lb.range_m - kC * (rover.sat.clock_bias_s - base.sat.clock_bias_s) + clock_rb_m;
  r.residual = (rover.pseudorange_m - base.pseudorange_m) - predicted;
  r.J_p = lr.J_range_p;
  r.J_clock = 1.0;
  return r;
}

MeasurementRow sd_range_rate(SatId sat, const SignalAtReceiver& rover, const SignalAtReceiver& base,
                             const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& v_ea_e,
                             const Eigen::Vector3d& p_eb_e, double drift_rb_mps) {
  const LineOfSight lr = line_of_sight(rover.sat, p_ea_e, v_ea_e);
  const LineOfSight lb = line_of_sight(base.sat, p_eb_e, Eigen::Vector3d::Zero());
  MeasurementRow r;
  r.sat = sat;
  const double predicted = lr.range_rate_mps - lb.range_rate_mps -
                           kC * (rover.sat.clock_drift_sps - base.sat.clock_drift_sps) + drift_rb_mps;
  r.residual = (rover.range_rate_mps - base.range_rate_mps) - predicted;
  r.J_p = lr.J_rate_p;
  r.J_v = lr.J_rate_v;
  r.J_drift = 1.0;
  return r;
}

double klobuchar_delay_m(const std::array<double, 8>& ab, GpsTime t, const Geodetic& llh,
                         const ElevationAzimuth& el_az) {
  // IS-GPS-200 Figure 20-4; angles in semicircles.
  const double el_sc = el_az.elevation / kPi;
  const double psi = 0.0137 / (el_sc + 0.11) - 0.022;  // Earth-centred angle
  double phi_i = llh.lat / kPi + psi * std::cos(el_az.azimuth);
  phi_i = std::clamp(phi_i, -0.416, 0.416);
  const double lambda_i = llh.lon / kPi + psi * std::sin(el_az.azimuth) / std::cos(phi_i * kPi);
  const double phi_m = phi_i + 0.064 * std::cos((lambda_i - 1.617) * kPi);  // geomagnetic latitude
  double local_time_s = 43200.0 * lambda_i + t.tow_s();
  local_time_s = std::fmod(local_time_s, 86400.0);
  if (local_time_s < 0.0) local_time_s += 86400.0;
  const double f = 1.0 + 16.0 * std::pow(0.53 - el_sc, 3);  // obliquity factor
  double amp = ab[0] + phi_m * (ab[1] + phi_m * (ab[2] + phi_m * ab[3]));
  double per = ab[4] + phi_m * (ab[5] + phi_m * (ab[6] + phi_m * ab[7]));
  amp = std::max(amp, 0.0);
  per = std::max(per, 72000.0);
  const double x = 2.0 * kPi * (local_time_s - 50400.0) / per;
  const double delay_s = std::abs(x) < 1.57 ? f * (5e-9 + amp * (1.0 - x * x / 2.0 + x * x * x * x / 24.0))
                                            : f * 5e-9;
  return kC * delay_s;
}

double saastamoinen_delay_m(const Geodetic& llh, double elevation_rad) {
  if (elevation_rad <= 0.0 || llh.h_m < -100.0 || llh.h_m > 1e4) return 0.0;
  // Standard atmosphere (Berg 1948) at the receiver height, 70 % relative humidity.
  const double h = std::max(llh.h_m, 0.0);
  const double pressure_hpa = 1013.25 * std::pow(1.0 - 2.2557e-5 * h, 5.2568);
  const double temp_k = 15.0 - 6.5e-3 * h + 273.15;
  const double humidity = 0.7;
  const double e_hpa = 6.108 * humidity * std::exp((17.15 * temp_k - 4684.0) / (temp_k - 38.45));
  const double z = kPi / 2.0 - elevation_rad;
  // Saastamoinen (1972) zenith delays mapped with 1/cos z.
  const double dry = 0.0022768 * pressure_hpa /
                     (1.0 - 0.00266 * std::cos(2.0 * llh.lat) - 0.00028 * h / 1e3) / std::cos(z);
  const double wet = 0.002277 * (1255.0 / temp_k + 0.05) * e_hpa / std::cos(z);
  return dry + wet;
}

double measurement_sigma(const WeightModel& m, double cn0_dbhz, double elevation_rad, bool doppler) {
  const double sigma0 = doppler ? m.doppler_sigma_zenith_mps : m.code_sigma_zenith_m;
  const double cn0 = std::isnan(cn0_dbhz) ? m.cn0_ref_dbhz : cn0_dbhz;
  const double cn0_factor = std::pow(10.0, std::max(0.0, m.cn0_ref_dbhz - cn0) / 20.0);
  const double el = std::max(elevation_rad, m.min_elevation_for_weight_rad);
  const double sin_el = std::sin(el);
  // Eq. W2: the DLL's squaring loss 1 + 2/((2 − d) T C/N0) grows like c² below cn0_ref (Kaplan & Hegarty eq. 7.88).
  const double loss = !doppler && m.code_squaring_loss > 0.0
                          ? std::sqrt((1.0 + m.code_squaring_loss * cn0_factor * cn0_factor) / (1.0 + m.code_squaring_loss))
                          : 1.0;
  // k = 1 in its closed form, so the default weights stay bit-identical to the model before eq. W1.
  if (m.elevation_weight == 1.0) return sigma0 * cn0_factor * loss / sin_el;
  return sigma0 * cn0_factor * loss * std::sqrt(1.0 + m.elevation_weight * (1.0 / (sin_el * sin_el) - 1.0));
}

}  // namespace pednav::gnss
