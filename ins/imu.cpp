// Increment integration with second-order coning and sculling compensation (docs/ins.md §2).
// Within a sample interval the rate and specific force are linear in time; the recursive forms below are the
// exact integrals of Bortz's rotation-vector rate and Savage's sculling integral to second order for that model
// (Savage 1998 Part 1 §"coning", Part 2 §"sculling"; Groves 2013 §5.5.4).
#include "ins/imu.hpp"

#include <Eigen/Geometry>
#include <cmath>

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
  // First grid point strictly after the first sample.
  const int64_t ns = s.t.ns();
  int64_t k = ns / period_ns_;
  if (k * period_ns_ <= ns) ++k;
  next_end_ = GpsTime::from_ns(k * period_ns_);
}

// One trapezoidal sub-interval a -> b (docs/ins.md eq. 2.3-2.6):
//   Δθ = (ω_a + ω_b) h/2,  Δu = (f_a + f_b) h/2,
//   β += 1/2 α × Δθ + h²/12 ω_a × ω_b                          (coning, rotation-vector integral)
//   S += 1/2 (α × Δu + υ × Δθ) + h²/12 (ω_a × f_b + f_a × ω_b)   (sculling integral 1/2 ∫(α×f + υ×ω))
//   α += Δθ,  υ += Δu   (α, υ accumulated since the interval start)
void IncrementIntegrator::integrate_segment(const ImuSample& a, const ImuSample& b) {
  const double h = static_cast<double>(b.t.ns() - a.t.ns()) * 1e-9;
  const Eigen::Vector3d dth = 0.5 * h * (a.omega_ib_b + b.omega_ib_b);
  const Eigen::Vector3d du = 0.5 * h * (a.f_ib_b + b.f_ib_b);
  const double h2_12 = h * h / 12.0;
  // cur_.dtheta_b / cur_.dv_b hold the running β and S until finish_at().
  cur_.dtheta_b += 0.5 * cur_.alpha_b.cross(dth) + h2_12 * a.omega_ib_b.cross(b.omega_ib_b);
  cur_.dv_b += 0.5 * (cur_.alpha_b.cross(du) + cur_.upsilon_b.cross(dth)) +
               h2_12 * (a.omega_ib_b.cross(b.f_ib_b) + a.f_ib_b.cross(b.omega_ib_b));
  cur_.alpha_b += dth;
  cur_.upsilon_b += du;
  cur_.samples += 1;
}

const ImuIncrement& IncrementIntegrator::finish_at(const ImuSample& end) {
  done_ = cur_;
  done_.t1 = end.t;
  done_.dt_s = static_cast<double>(end.t.ns() - cur_.t0.ns()) * 1e-9;
  const Eigen::Vector3d beta = cur_.dtheta_b, scul = cur_.dv_b;
  done_.dtheta_b = cur_.alpha_b + (options_.coning ? beta : Eigen::Vector3d::Zero());
  done_.dv_b = cur_.upsilon_b;
  if (options_.sculling) done_.dv_b += 0.5 * cur_.alpha_b.cross(cur_.upsilon_b) + scul;  // rotation + sculling
  done_.omega_end_b = end.omega_ib_b;
  done_.f_end_b = end.f_ib_b;
  cur_ = ImuIncrement{};
  cur_.t0 = end.t;
  next_end_ = next_end_.plus_ns(period_ns_);
  return done_;
}

bool IncrementIntegrator::flush(ImuIncrement& out) {
  if (!has_last_ || cur_.samples == 0) return false;
  out = finish_at(last_);
  return true;
}

std::vector<ImuIncrement> integrate_all(const std::vector<ImuSample>& samples, const IncrementOptions& options) {
  std::vector<ImuIncrement> out;
  IncrementIntegrator integrator(options);
  for (const auto& s : samples) integrator.push(s, [&](const ImuIncrement& inc) { out.push_back(inc); });
  return out;
}

}  // namespace pednav::ins
