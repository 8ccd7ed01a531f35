// Precise ECEF mechanization (docs/ins.md §3). Order of one step (Groves 2013 §5.2, with the precision forms
// of §5.5.1-5.5.3):
//   (3.1) R_e_b(+) = exp(-[ω_ie×]Δt) R_e_b(-) exp([Δθ×])          attitude, exact for constant Earth rate
//   (3.2) Δv_sf_e = R_e_b(-) Δv_b - 1/2 ω_ie × (R_e_b(-) υ) Δt    specific-force transformation
//   (3.3) v_pred = v(-) + Δv_sf_e + (g(p(-)) - 2 ω_ie × v(-)) Δt    predictor
//   (3.4) v(+) = v(-) + Δv_sf_e + (g(p_mid) - 2 ω_ie × v_mid) Δt,  v_mid = (v(-) + v_pred)/2,
//         p_mid = p(-) + (v(-) + v_mid) Δt/4                       gravity at the mid-point, Coriolis at mean v
//   (3.5) p(+) = p(-) + (v(-) + v(+)) Δt/2                          trapezoidal position
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
  const Eigen::Vector3d bg_dt = e.b_g * inc.dt_s, ba_dt = e.b_a * inc.dt_s;
  out.alpha_b = remove(inc.alpha_b, bg_dt, e.s_g);
  out.dtheta_b = remove(inc.dtheta_b, bg_dt, e.s_g);
  out.upsilon_b = remove(inc.upsilon_b, ba_dt, e.s_a);
  out.dv_b = remove(inc.dv_b, ba_dt, e.s_a);
  out.omega_end_b = remove(inc.omega_end_b, e.b_g, e.s_g);
  out.f_end_b = remove(inc.f_end_b, e.b_a, e.s_a);
  return out;
}

ImuSample correct_sample(const ImuSample& s, const ImuErrors& e) {
  ImuSample out = s;
  out.omega_ib_b = remove(s.omega_ib_b, e.b_g, e.s_g);
  out.f_ib_b = remove(s.f_ib_b, e.b_a, e.s_a);
  return out;
}

Eigen::Vector3d specific_force_increment_e(const NavState& prev, const ImuIncrement& inc) {
  const Eigen::Matrix3d R0 = prev.R_e_b();
  return R0 * inc.dv_b - 0.5 * inc.dt_s * kOmegaIE_e.cross(R0 * inc.upsilon_b);
}

NavState mechanize(const NavState& prev, const ImuIncrement& inc) {
  const double dt = inc.dt_s;
  NavState next;
  next.t = inc.t1;
  next.q_e_b = (quat_exp(-kOmegaIE_e * dt) * prev.q_e_b * quat_exp(inc.dtheta_b)).normalized();  // (3.1)
  const Eigen::Vector3d dv_sf_e = specific_force_increment_e(prev, inc);                         // (3.2)
  const Eigen::Vector3d v_pred =
      prev.v_eb_e + dv_sf_e + (gravity_ecef(prev.p_eb_e) - 2.0 * kOmegaIE_e.cross(prev.v_eb_e)) * dt;  // (3.3)
  const Eigen::Vector3d v_mid = 0.5 * (prev.v_eb_e + v_pred);
  const Eigen::Vector3d p_mid = prev.p_eb_e + 0.25 * dt * (prev.v_eb_e + v_mid);
  next.v_eb_e = prev.v_eb_e + dv_sf_e + (gravity_ecef(p_mid) - 2.0 * kOmegaIE_e.cross(v_mid)) * dt;  // (3.4)
  next.p_eb_e = prev.p_eb_e + 0.5 * dt * (prev.v_eb_e + next.v_eb_e);                            // (3.5)
  return next;
}

}  // namespace pednav::ins
