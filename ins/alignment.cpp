// SPDX-License-Identifier: BSD-2-Clause
// Coarse alignment (docs/ins.md §6). At rest f_ib_b = -R_b_n g_n with g_n = (0, 0, g), so
// roll = atan2(-f_y, -f_z), pitch = atan2(f_x, sqrt(f_y^2 + f_z^2)) (Groves 2013 §5.6.2, eq. 5.101 form).
#include "ins/alignment.hpp"

#include <cmath>
#include <cstdio>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "ins/gravity.hpp"

namespace pednav::ins {
namespace {

struct WindowStats {
  Eigen::Vector3d mean_w = Eigen::Vector3d::Zero(), mean_f = Eigen::Vector3d::Zero();
  Eigen::Vector3d std_w = Eigen::Vector3d::Zero(), std_f = Eigen::Vector3d::Zero();
};

WindowStats stats(const std::vector<ImuSample>& s, int begin, int end) {
  WindowStats st;
  const double n = end - begin;
  for (int i = begin; i < end; ++i) {
    st.mean_w += s[i].omega_ib_b;
    st.mean_f += s[i].f_ib_b;
  }
  st.mean_w /= n;
  st.mean_f /= n;
  for (int i = begin; i < end; ++i) {
    st.std_w += (s[i].omega_ib_b - st.mean_w).cwiseAbs2();
    st.std_f += (s[i].f_ib_b - st.mean_f).cwiseAbs2();
  }
  st.std_w = (st.std_w / n).cwiseSqrt();
  st.std_f = (st.std_f / n).cwiseSqrt();
  return st;
}

std::string fmt(const char* f, double a, double b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

}  // namespace

Expected<Levelling> coarse_level(const std::vector<ImuSample>& samples, const Eigen::Vector3d& p_eb_e, double yaw_rad,
                                 const StillnessOptions& o) {
  if (samples.size() < 2) return make_error("levelling: need at least 2 samples, got " + std::to_string(samples.size()));
  const int n = static_cast<int>(samples.size());
  Levelling lv;
  lv.samples = n;
  lv.duration_s = samples.back().t - samples.front().t;
  if (lv.duration_s < o.min_duration_s)
    return make_error(fmt("levelling: still window of %.3f s is shorter than the required %.3f s", lv.duration_s,
                          o.min_duration_s));
  const WindowStats st = stats(samples, 0, n);
  lv.mean_f_ib_b = st.mean_f;
  lv.mean_omega_ib_b = st.mean_w;
  lv.gyro_std_radps = st.std_w;
  lv.accel_std_mps2 = st.std_f;
  if (st.std_w.maxCoeff() > o.max_gyro_std_radps)
    return make_error(fmt("levelling: not still: gyro standard deviation %.4f rad/s exceeds %.4f rad/s",
                          st.std_w.maxCoeff(), o.max_gyro_std_radps));
  if (st.std_f.maxCoeff() > o.max_accel_std_mps2)
    return make_error(fmt("levelling: not still: specific-force standard deviation %.4f m/s^2 exceeds %.4f m/s^2",
                          st.std_f.maxCoeff(), o.max_accel_std_mps2));
  const double g = gravity_ecef(p_eb_e).norm();
  if (std::abs(st.mean_f.norm() - g) > o.max_gravity_error_mps2)
    return make_error(fmt("levelling: mean |f| = %.3f m/s^2 is not local gravity %.3f m/s^2 (accelerometer unit or "
                          "scale wrong?)",
                          st.mean_f.norm(), g));
  const Eigen::Vector3d& f = st.mean_f;
  lv.roll = std::atan2(-f.y(), -f.z());
  lv.pitch = std::atan2(f.x(), std::sqrt(f.y() * f.y() + f.z() * f.z()));
  const NavState s = nav_state_at_rest(samples.front().t, p_eb_e, lv.roll, lv.pitch, yaw_rad);
  const Eigen::Vector3d omega_ie_b = s.R_e_b().transpose() * Eigen::Vector3d(0.0, 0.0, wgs84::kOmegaIE_radps);
  lv.gyro_bias_b = st.mean_w - omega_ie_b;
  return lv;
}

double still_gyro_bias_d2(const Levelling& lv, double gyro_bias_initial_radps, double gyro_arw) {
  const double var_mean = lv.duration_s > 0.0 ? gyro_arw * gyro_arw / lv.duration_s : 0.0;
  return lv.gyro_bias_b.squaredNorm() / (gyro_bias_initial_radps * gyro_bias_initial_radps + var_mean);
}

NavState nav_state_at_rest(GpsTime t, const Eigen::Vector3d& p_eb_e, double roll, double pitch, double yaw) {
  const Geodetic llh = geodetic_from_ecef(p_eb_e);
  NavState s;
  s.t = t;
  s.p_eb_e = p_eb_e;
  s.v_eb_e.setZero();
  s.q_e_b = Eigen::Quaterniond(R_e_n(llh.lat, llh.lon) * R_n_b_from_euler(roll, pitch, yaw)).normalized();
  return s;
}

double heading_from_magnetometer(const Eigen::Vector3d& m_b, double roll, double pitch, double declination_rad) {
  // Level the measured field with roll and pitch only (yaw = 0): m_h = Ry(pitch) Rx(roll) m_b; then the
  // field's horizontal direction in the yaw-free frame is at -yaw from north.
  const Eigen::Vector3d m_h = R_n_b_from_euler(roll, pitch, 0.0) * m_b;
  return wrap_pi(std::atan2(-m_h.y(), m_h.x()) + declination_rad);
}

}  // namespace pednav::ins
