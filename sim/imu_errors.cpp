// SPDX-License-Identifier: BSD-2-Clause
// IMU error model (docs/sim.md §4). Per axis and sample at rate f_s:
//   x_meas = M (I + diag(s)) x_true + b0 + b_gm(t) + b_rw(t) + G f_true (gyro only) + n,  n ~ N(0, N_d^2 f_s)
// with N_d the noise density (ARW/VRW in rad/sqrt(s), m/s/sqrt(s)), b_gm a first-order Gauss-Markov process
// (sigma = bias instability, tau), b_rw a random walk; then quantization to the resolution and clipping at the
// range (Groves 2013 §4.4; IEEE Std 952-1997 for the noise terms).
#include "sim/imu_errors.hpp"

#include <algorithm>
#include <cmath>

#include "sim/random.hpp"

namespace pednav::sim {
namespace {

Eigen::Vector3d normal3(Rng& r) { return {r.normal(), r.normal(), r.normal()}; }
Eigen::Matrix3d misalignment(Rng& r, double sigma) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i != j) M(i, j) = sigma * r.normal();
  return M;
}
double finish(double v, double quantum, double range, bool& clipped) {
  if (quantum > 0.0) v = quantum * std::round(v / quantum);
  if (range > 0.0 && std::abs(v) > range) {
    v = std::copysign(range, v);
    clipped = true;
  }
  return v;
}

// Bias process per axis: Gauss-Markov (exact discretization) + random walk.
struct BiasProcess {
  double sigma_gm, tau, rw;
  Eigen::Vector3d gm = Eigen::Vector3d::Zero(), walk = Eigen::Vector3d::Zero();
  void init(Rng& r) {
    if (sigma_gm > 0.0 && tau > 0.0) gm = sigma_gm * normal3(r);
  }
  Eigen::Vector3d step(double dt, Rng& r) {
    if (sigma_gm > 0.0 && tau > 0.0) {
      const double phi = std::exp(-dt / tau);
      gm = phi * gm + sigma_gm * std::sqrt(1.0 - phi * phi) * normal3(r);
    }
    if (rw > 0.0) walk += rw * std::sqrt(dt) * normal3(r);
    return gm + walk;
  }
};

}  // namespace

std::vector<ins::ImuSample> corrupt_imu(const std::vector<ins::ImuSample>& exact, const ImuOptions& o, uint64_t seed,
                                        ImuErrorTruth* truth) {
  ImuErrorTruth tr;
  const bool mounted = !o.R_b_s.isIdentity(0.0);
  if (!o.errors) {
    if (truth) *truth = tr;
    if (!mounted) return exact;
    std::vector<ins::ImuSample> out = exact;
    for (auto& m : out) {
      m.omega_ib_b = o.R_b_s.transpose() * m.omega_ib_b;
      m.f_ib_b = o.R_b_s.transpose() * m.f_ib_b;
    }
    return out;
  }
  Rng r(seed, kStreamImu);
  const ins::ImuSpec& s = o.spec;
  tr.b_g0 = s.gyro_bias_initial * normal3(r);
  tr.b_a0 = s.accel_bias_initial * normal3(r);
  tr.s_g = s.gyro_scale_sigma * normal3(r);
  tr.s_a = s.accel_scale_sigma * normal3(r);
  tr.M_g = misalignment(r, o.misalignment_sigma_rad);
  tr.M_a = misalignment(r, o.misalignment_sigma_rad);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) tr.G_g(i, j) = o.gyro_g_sensitivity_sigma * r.normal();
  BiasProcess bg{s.gyro_bias_instability, s.gyro_bias_tau_s, s.gyro_bias_rw};
  BiasProcess ba{s.accel_bias_instability, s.accel_bias_tau_s, s.accel_bias_rw};
  bg.init(r);
  ba.init(r);
  const Eigen::Matrix3d Kg = tr.M_g * (Eigen::Vector3d::Ones() + tr.s_g).asDiagonal();
  const Eigen::Matrix3d Ka = tr.M_a * (Eigen::Vector3d::Ones() + tr.s_a).asDiagonal();
  const double sq_rate = std::sqrt(o.rate_hz), dt = 1.0 / o.rate_hz;
  std::vector<ins::ImuSample> out;
  out.reserve(exact.size());
  for (size_t k = 0; k < exact.size(); ++k) {
    ins::ImuSample e = exact[k];
    if (mounted) {  // the sensor's axes (its errors act on them)
      e.omega_ib_b = o.R_b_s.transpose() * e.omega_ib_b;
      e.f_ib_b = o.R_b_s.transpose() * e.f_ib_b;
    }
    const Eigen::Vector3d bgk = k == 0 ? Eigen::Vector3d(bg.gm + bg.walk) : bg.step(dt, r);
    const Eigen::Vector3d bak = k == 0 ? Eigen::Vector3d(ba.gm + ba.walk) : ba.step(dt, r);
    if (k == 0) tr.b_g_first = tr.b_g0 + bgk;
    const Eigen::Vector3d w = Kg * e.omega_ib_b + tr.b_g0 + bgk + tr.G_g * e.f_ib_b + s.gyro_arw * sq_rate * normal3(r);
    const Eigen::Vector3d f = Ka * e.f_ib_b + tr.b_a0 + bak + s.accel_vrw * sq_rate * normal3(r);
    ins::ImuSample m;
    m.t = e.t;
    bool clipped = false;
    for (int i = 0; i < 3; ++i) {
      m.omega_ib_b(i) = finish(w(i), o.gyro_quantum_radps, s.gyro_range, clipped);
      m.f_ib_b(i) = finish(f(i), o.accel_quantum_mps2, s.accel_range, clipped);
    }
    if (clipped) ++tr.saturated_samples;
    out.push_back(m);
  }
  if (truth) *truth = tr;
  return out;
}

}  // namespace pednav::sim
