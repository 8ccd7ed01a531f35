// SPDX-License-Identifier: BSD-2-Clause
// Increment integration (docs/ins.md §2): two-speed structure of Savage 1998 (Parts 1-2) with the body-frame
// rotation/velocity/position increments composed at the IMU rate; coning and sculling terms per sub-interval
// (Groves 2013 §5.5.4).
#include "ins/imu.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "core/rotation.hpp"

namespace pednav::ins {

IncrementIntegrator::IncrementIntegrator(IncrementOptions options)
    : options_(options), period_ns_(std::llround(1e9 / options.rate_hz)) {
  if (period_ns_ < 1) period_ns_ = 1;
}

ImuSample IncrementIntegrator::interpolate(const ImuSample& a, const ImuSample& b, GpsTime t) {
  if (t == b.t) return b;
  if (t == a.t) return a;
  const double w = static_cast<double>(t.ns() - a.t.ns()) / static_cast<double>(b.t.ns() - a.t.ns());
  ImuSample m;
  m.t = t;
  m.omega_ib_b = a.omega_ib_b + w * (b.omega_ib_b - a.omega_ib_b);
  m.f_ib_b = a.f_ib_b + w * (b.f_ib_b - a.f_ib_b);
  return m;
}

void IncrementIntegrator::begin(const ImuSample& s) {
  has_last_ = true;
  last_ = s;
  cur_ = ImuIncrement{};
  cur_.t0 = s.t;
  q_acc_.setIdentity();
  // First grid point strictly after the first sample.
  const int64_t ns = s.t.ns();
  int64_t k = ns / period_ns_;
  if (k * period_ns_ <= ns) ++k;
  next_end_ = GpsTime::from_ns(k * period_ns_);
}

// One sub-interval a -> b of length h, rates and specific force linear in time (docs/ins.md eq. 2.1-2.6):
//   Δθ = (ω_a + ω_b) h/2,  Δu = (f_a + f_b) h/2
//   φ_k  = Δθ + h²/12 ω_a × ω_b                                  (2.2) rotation vector of the sub-interval
//   δv_k = Δu + 1/2 Δθ × Δu + h²/12 (ω_a × f_b + f_a × ω_b)        (2.3) rotation + sculling, in b(a)
//   δp_k = h²/6 (2 f_a + f_b)                                      (2.4) double integral, in b(a)
//   P += V h + C δp_k,   V += C δv_k,   C ← C exp(φ_k)             (2.5) C = R_b(t0)_b(a)
// (2.2)/(2.3) are the exact integrals of Bortz's equation and of Savage's sculling integral to second order
// for the linear model; composing them per sub-interval leaves only O(h³) errors per IMU sample.
void IncrementIntegrator::integrate_segment(const ImuSample& a, const ImuSample& b) {
  const double h = static_cast<double>(b.t.ns() - a.t.ns()) * 1e-9;
  const Eigen::Vector3d dth = 0.5 * h * (a.omega_ib_b + b.omega_ib_b);
  const Eigen::Vector3d du = 0.5 * h * (a.f_ib_b + b.f_ib_b);
  const double h2_12 = h * h / 12.0;
  const Eigen::Vector3d phi = dth + h2_12 * a.omega_ib_b.cross(b.omega_ib_b);
  const Eigen::Vector3d dv = du + 0.5 * dth.cross(du) + h2_12 * (a.omega_ib_b.cross(b.f_ib_b) + a.f_ib_b.cross(b.omega_ib_b));
  const Eigen::Vector3d dp = (h * h / 6.0) * (2.0 * a.f_ib_b + b.f_ib_b);
  const Eigen::Matrix3d C = q_acc_.toRotationMatrix();
  cur_.dp_b += cur_.dv_b * h + C * dp;
  cur_.dv_b += C * dv;
  q_acc_ = (q_acc_ * quat_exp(phi)).normalized();
  cur_.alpha_b += dth;
  cur_.upsilon_b += du;
  cur_.samples += 1;
}

const ImuIncrement& IncrementIntegrator::finish_at(const ImuSample& end) {
  done_ = cur_;
  done_.t1 = end.t;
  done_.dt_s = static_cast<double>(end.t.ns() - cur_.t0.ns()) * 1e-9;
  done_.dtheta_b = options_.coning ? quat_log(q_acc_) : cur_.alpha_b;
  if (!options_.sculling) {
    done_.dv_b = cur_.upsilon_b;
    done_.dp_b = 0.5 * done_.dt_s * cur_.upsilon_b;
  }
  done_.omega_end_b = end.omega_ib_b;
  done_.f_end_b = end.f_ib_b;
  cur_ = ImuIncrement{};
  cur_.t0 = end.t;
  q_acc_.setIdentity();
  next_end_ = next_end_.plus_ns(period_ns_);
  return done_;
}

bool IncrementIntegrator::flush(ImuIncrement& out) {
  if (!has_last_ || cur_.samples == 0) return false;
  out = finish_at(last_);
  return true;
}

bool IncrementIntegrator::cut(ImuIncrement& out) {
  if (!has_last_ || cur_.samples == 0) return false;
  const GpsTime grid_end = next_end_;
  out = finish_at(last_);
  next_end_ = grid_end;  // finish_at moved it one period on: the grid stays where it was
  return true;
}

std::vector<ImuIncrement> integrate_all(const std::vector<ImuSample>& samples, const IncrementOptions& options) {
  std::vector<ImuIncrement> out;
  IncrementIntegrator integrator(options);
  for (const auto& s : samples) integrator.push(s, [&](const ImuIncrement& inc) { out.push_back(inc); });
  return out;
}

}  // namespace pednav::ins
