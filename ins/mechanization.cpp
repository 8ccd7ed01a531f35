// SPDX-License-Identifier: BSD-2-Clause
// Precise ECEF mechanization (docs/ins.md §3), Groves 2013 §5.2 with the precision forms of §5.5.1-5.5.3.
// Inputs are the body-frame increments of the interval (C(t) = R_b(t0)_b(t)): Δθ = log C(t1), V = ∫ C f dt,
// P = ∫∫ C f (identity: ∫ t C f dt = V Δt - P). Order of one step:
//   (3.1) R_e_b(+) = exp(-[ω_ie×]Δt) R_e_b(-) exp([Δθ×])                attitude, exact for constant Earth rate
//   (3.2) Δv_sf_e = R0 V - ω_ie × R0 (V Δt - P)                          specific force in e incl. Earth rotation
//   (3.3) Δp_sf_e = R0 P - Δt²/6 ω_ie × (R0 V)                           its double integral
//   (3.4) p(+) = p(-) + v(-) Δt + Δp_sf_e + Δt²/2 (g(p(-) + v(-)Δt/2) - 2 ω_ie × v(-))
//   (3.5) v(+) = v(-) + Δv_sf_e + Δt (g(p_mid) - 2 ω_ie × v_mean),  v_mean = (p(+) - p(-))/Δt,  p_mid = (p(-)+p(+))/2
#include "ins/mechanization.hpp"

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "ins/gravity.hpp"

namespace pednav::ins {
namespace {
const Eigen::Vector3d kOmegaIE_e(0.0, 0.0, wgs84::kOmegaIE_radps);

Eigen::Vector3d remove(const Eigen::Vector3d& v, const Eigen::Vector3d& bias_times_dt, const Eigen::Vector3d& scale) {
  return ((v - bias_times_dt).array() / (1.0 + scale.array())).matrix();
}
}  // namespace

ImuIncrement correct_increment(const ImuIncrement& inc, const ImuErrors& e) {
  ImuIncrement out = inc;
  const Eigen::Vector3d ba_dt = e.b_a * inc.dt_s;
  out.upsilon_b = remove(inc.upsilon_b, ba_dt, e.s_a);
  out.dv_b = remove(inc.dv_b, ba_dt, e.s_a);
  out.dp_b = remove(inc.dp_b, 0.5 * inc.dt_s * ba_dt, e.s_a);
  out.f_end_b = remove(inc.f_end_b, e.b_a, e.s_a);
  // ∫ G f dt = G υ (corrected specific force): the g-sensitive part of the angle increment.
  const Eigen::Vector3d bg_dt = e.b_g * inc.dt_s + e.G_g * out.upsilon_b;
  out.alpha_b = remove(inc.alpha_b, bg_dt, e.s_g);
  out.dtheta_b = remove(inc.dtheta_b, bg_dt, e.s_g);
  out.omega_end_b = remove(inc.omega_end_b, e.b_g + e.G_g * out.f_end_b, e.s_g);
  return out;
}

ImuSample correct_sample(const ImuSample& s, const ImuErrors& e) {
  ImuSample out = s;
  out.f_ib_b = remove(s.f_ib_b, e.b_a, e.s_a);
  out.omega_ib_b = remove(s.omega_ib_b, e.b_g + e.G_g * out.f_ib_b, e.s_g);
  return out;
}

Eigen::Vector3d specific_force_increment_e(const NavState& prev, const ImuIncrement& inc) {
  const Eigen::Matrix3d R0 = prev.R_e_b();
  return R0 * inc.dv_b - kOmegaIE_e.cross(R0 * (inc.dv_b * inc.dt_s - inc.dp_b));  // (3.2)
}

NavState mechanize(const NavState& prev, const ImuIncrement& inc) {
  const double dt = inc.dt_s;
  const Eigen::Matrix3d R0 = prev.R_e_b();
  NavState next;
  next.t = inc.t1;
  next.q_e_b = (quat_exp(-kOmegaIE_e * dt) * prev.q_e_b * quat_exp(inc.dtheta_b)).normalized();  // (3.1)
  const Eigen::Vector3d dv_sf_e = specific_force_increment_e(prev, inc);                         // (3.2)
  const Eigen::Vector3d dp_sf_e = R0 * inc.dp_b - (dt * dt / 6.0) * kOmegaIE_e.cross(R0 * inc.dv_b);  // (3.3)
  const Eigen::Vector3d g_half = gravity_ecef(prev.p_eb_e + 0.5 * dt * prev.v_eb_e);
  next.p_eb_e = prev.p_eb_e + prev.v_eb_e * dt + dp_sf_e +
                0.5 * dt * dt * (g_half - 2.0 * kOmegaIE_e.cross(prev.v_eb_e));  // (3.4)
  const Eigen::Vector3d v_mean = (next.p_eb_e - prev.p_eb_e) / dt;
  const Eigen::Vector3d p_mid = 0.5 * (prev.p_eb_e + next.p_eb_e);
  next.v_eb_e = prev.v_eb_e + dv_sf_e + dt * (gravity_ecef(p_mid) - 2.0 * kOmegaIE_e.cross(v_mean));  // (3.5)
  return next;
}

}  // namespace pednav::ins
