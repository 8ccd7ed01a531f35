// SPDX-License-Identifier: BSD-2-Clause
// Analytic test motions with exact IMU synthesis (ECEF mechanization equations run backwards):
//   omega_ib_b = omega_eb_b + R_b_e omega_ie_e,   f_ib_b = R_b_e (a_e - g(p_e) + 2 omega_ie x v_e).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "ins/alignment.hpp"
#include "ins/gravity.hpp"
#include "ins/imu.hpp"
#include "ins/nav_state.hpp"

namespace pednav::test {

/// True kinematic state at one instant (ECEF).
struct Kinematics {
  Eigen::Vector3d p_e, v_e, a_e;
  Eigen::Matrix3d R_e_b;
  Eigen::Vector3d omega_eb_b;
};

inline ins::ImuSample imu_from_kinematics(GpsTime t, const Kinematics& k) {
  const Eigen::Vector3d w_ie(0.0, 0.0, wgs84::kOmegaIE_radps);
  ins::ImuSample s;
  s.t = t;
  s.omega_ib_b = k.omega_eb_b + k.R_e_b.transpose() * w_ie;
  s.f_ib_b = k.R_e_b.transpose() * (k.a_e - ins::gravity_ecef(k.p_e) + 2.0 * w_ie.cross(k.v_e));
  return s;
}

inline ins::NavState nav_from_kinematics(GpsTime t, const Kinematics& k) {
  ins::NavState s;
  s.t = t;
  s.p_eb_e = k.p_e;
  s.v_eb_e = k.v_e;
  s.q_e_b = Eigen::Quaterniond(k.R_e_b).normalized();
  return s;
}

/// A state at rest at latitude/longitude [deg], height [m], roll/pitch/yaw [rad].
inline ins::NavState nav_state_from_ll(GpsTime t, double lat_deg, double lon_deg, double h_m, double roll,
                                       double pitch, double yaw) {
  return ins::nav_state_at_rest(t, ecef_from_geodetic({lat_deg * kDegToRad, lon_deg * kDegToRad, h_m}), roll, pitch,
                                yaw);
}

/// Foot-like gait in a tangent plane fixed at a start point: still, then strides of period T with stance
/// fraction 0.3; during swing the foot moves L forward along the stride heading, lifts H, pitches with peak
/// rate `peak_pitch_rate`, rolls a little and yaws by dpsi per stride (curved path). All derivatives analytic.
struct FootMotion {
  Eigen::Vector3d p0_e = ecef_from_geodetic({51.08 * kDegToRad, -114.13 * kDegToRad, 1100.0});  // Calgary
  double still_s = 2.0, T = 1.1, stance_frac = 0.3, L = 1.4, H = 0.12, dpsi = 0.12, roll_amp = 0.08;
  double peak_pitch_rate = 7.0;  // [rad/s]
  double pitch_amp = 0.0;        // set by the constructor from peak_pitch_rate

  FootMotion() {
    // Normalized pitch profile θ(u) = sin(2πu) sin²(πu); find its peak rate numerically.
    double peak = 0.0;
    for (int i = 0; i <= 20000; ++i) peak = std::max(peak, std::abs(dshape(i / 20000.0)));
    pitch_amp = peak_pitch_rate * swing() / peak;
  }
  double swing() const { return T * (1.0 - stance_frac); }
  static double shape(double u) { return std::sin(2 * kPi * u) * std::pow(std::sin(kPi * u), 2); }
  static double dshape(double u) {  // d/du
    return 2 * kPi * std::cos(2 * kPi * u) * std::pow(std::sin(kPi * u), 2) +
           std::sin(2 * kPi * u) * kPi * std::sin(2 * kPi * u);
  }

  Kinematics at(double t) const {
    const double Ts = swing();
    double yaw0 = 0.0, x0 = 0.0, y0 = 0.0;
    double u = -1.0;  // <0: stance
    if (t > still_s) {
      const double tt = t - still_s;
      const int k = static_cast<int>(std::floor(tt / T));
      const double s = tt - k * T;
      // Completed strides before k: position and yaw in closed form (sum over strides).
      for (int j = 0; j < k; ++j) {
        const double chi = j * dpsi + 0.5 * dpsi;
        x0 += L * std::cos(chi);
        y0 += L * std::sin(chi);
      }
      yaw0 = k * dpsi;
      const double stance = T * stance_frac;
      if (s > stance) u = (s - stance) / Ts;
    }
    double n = x0, e = y0, d = 0.0, vn = 0, ve = 0, vd = 0, an = 0, ae = 0, ad = 0;
    double roll = 0, pitch = 0, yaw = yaw0, droll = 0, dpitch = 0, dyaw = 0;
    if (u >= 0.0) {
      const double w = 2 * kPi * u;
      const double chi = yaw0 + 0.5 * dpsi;
      const double x = L * (u - std::sin(w) / (2 * kPi)), dx = L / Ts * (1 - std::cos(w)),
                   ddx = L / (Ts * Ts) * 2 * kPi * std::sin(w);
      n += x * std::cos(chi);
      e += x * std::sin(chi);
      vn = dx * std::cos(chi);
      ve = dx * std::sin(chi);
      an = ddx * std::cos(chi);
      ae = ddx * std::sin(chi);
      const double sp = std::sin(kPi * u), cp = std::cos(kPi * u);
      d = -H * std::pow(sp, 4);
      vd = -H * 4 * kPi / Ts * std::pow(sp, 3) * cp;
      ad = -H * 4 * kPi * kPi / (Ts * Ts) * (3 * sp * sp * cp * cp - std::pow(sp, 4));
      pitch = pitch_amp * shape(u);
      dpitch = pitch_amp * dshape(u) / Ts;
      roll = roll_amp * std::sin(w) * sp * sp;
      droll = roll_amp * (2 * kPi * std::cos(w) * sp * sp + std::sin(w) * kPi * 2 * sp * cp) / Ts;
      yaw = yaw0 + dpsi * (u - std::sin(w) / (2 * kPi));
      dyaw = dpsi / Ts * (1 - std::cos(w));
    }
    const Geodetic llh0 = geodetic_from_ecef(p0_e);
    const Eigen::Matrix3d Ren = R_e_n(llh0.lat, llh0.lon);
    Kinematics k;
    k.p_e = p0_e + Ren * Eigen::Vector3d(n, e, d);
    k.v_e = Ren * Eigen::Vector3d(vn, ve, vd);
    k.a_e = Ren * Eigen::Vector3d(an, ae, ad);
    k.R_e_b = Ren * R_n_b_from_euler(roll, pitch, yaw);
    // z-y-x Euler rates -> body rates.
    const double sr = std::sin(roll), cr = std::cos(roll), st = std::sin(pitch), ct = std::cos(pitch);
    k.omega_eb_b = Eigen::Vector3d(droll - dyaw * st, dpitch * cr + dyaw * ct * sr, -dpitch * sr + dyaw * ct * cr);
    return k;
  }

  /// IMU samples at rate_hz from t = 0 to duration_s (GPST week 0 + t).
  std::vector<ins::ImuSample> samples(double rate_hz, double duration_s, GpsTime t0 = GpsTime()) const {
    std::vector<ins::ImuSample> out;
    const int64_t step_ns = std::llround(1e9 / rate_hz);
    for (int64_t i = 0; i * step_ns <= std::llround(duration_s * 1e9); ++i) {
      out.push_back(imu_from_kinematics(t0.plus_ns(i * step_ns), at(i * step_ns * 1e-9)));
    }
    return out;
  }
};

}  // namespace pednav::test
