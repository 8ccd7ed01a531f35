// SPDX-License-Identifier: BSD-2-Clause
// IMU samples and their integration into coning/sculling-compensated increments over mechanization intervals.
// Model and equations: docs/ins.md §2 (Savage 1998 Parts 1-2; Groves 2013 §5.5.4).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "core/time.hpp"

namespace pednav::ins {

/// One IMU sample: instantaneous angular rate and specific force at time t, resolved in the IMU body frame.
struct ImuSample {
  GpsTime t;                                            ///< sample time (GPST)
  Eigen::Vector3d omega_ib_b = Eigen::Vector3d::Zero(); ///< angular rate of b w.r.t. inertial space [rad/s]
  Eigen::Vector3d f_ib_b = Eigen::Vector3d::Zero();     ///< specific force [m/s^2]
};

/// Sensor increments over one mechanization interval [t0, t1], resolved in the body frame b(t0).
struct ImuIncrement {
  GpsTime t0;                                               ///< interval start (GPST)
  GpsTime t1;                                               ///< interval end (GPST)
  double dt_s = 0.0;                                        ///< t1 - t0 [s]
  Eigen::Vector3d alpha_b = Eigen::Vector3d::Zero();        ///< plain angle increment  ∫ω dt [rad]
  Eigen::Vector3d upsilon_b = Eigen::Vector3d::Zero();      ///< plain velocity increment ∫f dt [m/s]
  Eigen::Vector3d dtheta_b = Eigen::Vector3d::Zero();       ///< rotation vector of R_b(t0)_b(t1) (coning included) [rad]
  Eigen::Vector3d dv_b = Eigen::Vector3d::Zero();           ///< ∫ R_b(t0)_b(t) f dt: velocity increment in b(t0), rotation + sculling included [m/s]
  Eigen::Vector3d dp_b = Eigen::Vector3d::Zero();           ///< ∫∫ R_b(t0)_b(s) f ds dt: position increment in b(t0) (scrolling included) [m]
  Eigen::Vector3d omega_end_b = Eigen::Vector3d::Zero();    ///< rate at t1 [rad/s] (for scale-factor Jacobians / detectors)
  Eigen::Vector3d f_end_b = Eigen::Vector3d::Zero();        ///< specific force at t1 [m/s^2]
  int samples = 0;                                          ///< IMU sub-intervals accumulated
};

/// Options of the increment integrator.
struct IncrementOptions {
  double rate_hz = 20.0;        ///< mechanization rate [Hz]; interval ends lie on the GPST grid k / rate_hz
  bool coning = true;           ///< compose the sub-interval rotations (otherwise dtheta = alpha: no coning correction)
  bool sculling = true;         ///< rotate sub-interval velocity/position increments (otherwise dv = upsilon, dp = upsilon dt/2)
};

/// Accumulates IMU samples (any rate, irregular spacing allowed) into increments over mechanization intervals.
/// Between two samples the rate and specific force are taken as linear in time; an interval end that falls
/// between samples is served by linear interpolation of the two samples. Any mechanization rate up to (and
/// above) the IMU rate works. Coning, sculling and scrolling are handled by a two-speed structure (Savage 1998):
/// the body-frame rotation, velocity and position increments are composed at the IMU rate (second-order
/// sub-interval terms, docs/ins.md eq. 2.1-2.6); the Earth/gravity part runs at the mechanization rate.
/// Interval ends lie on the GPST grid of integer multiples of the period (1e9/rate_hz ns, rounded).
class IncrementIntegrator {
 public:
  explicit IncrementIntegrator(IncrementOptions options = {});
  /// Add the next sample (time strictly increasing, GPST); `sink(const ImuIncrement&)` is called for every
  /// interval this sample completes (none, one, or several across a gap).
  template <typename Sink>
  void push(const ImuSample& sample, Sink&& sink) {
    if (!has_last_) {
      begin(sample);
      return;
    }
    ImuSample a = last_;
    while (sample.t >= next_end_) {
      const ImuSample m = interpolate(a, sample, next_end_);
      integrate_segment(a, m);
      sink(static_cast<const ImuIncrement&>(finish_at(m)));
      a = m;
    }
    if (a.t < sample.t) integrate_segment(a, sample);
    last_ = sample;
  }
  /// Close the current partial interval at the last sample (end of data); false if it is empty.
  bool flush(ImuIncrement& out);
  /// Close the current partial interval at the last sample without moving the grid: the next interval ends at the
  /// same grid point as this one would have (a short stance's ZUPT, ins::zupt_forced_interval_ends); false if empty.
  bool cut(ImuIncrement& out);
  /// Period of the mechanization grid [ns].
  int64_t period_ns() const { return period_ns_; }
  const IncrementOptions& options() const { return options_; }

  /// Linear interpolation of two samples at time t (GPST), a.t <= t <= b.t.
  static ImuSample interpolate(const ImuSample& a, const ImuSample& b, GpsTime t);

 private:
  void begin(const ImuSample& s);
  void integrate_segment(const ImuSample& a, const ImuSample& b);
  const ImuIncrement& finish_at(const ImuSample& end);

  IncrementOptions options_;
  int64_t period_ns_;
  bool has_last_ = false;
  ImuSample last_;
  ImuIncrement cur_;
  ImuIncrement done_;
  Eigen::Quaterniond q_acc_ = Eigen::Quaterniond::Identity();  // R_b(t0)_b(current)
  GpsTime next_end_;
};

/// All complete increments of a sample sequence (time-ordered, GPST) at the given options; the trailing
/// partial interval is dropped.
std::vector<ImuIncrement> integrate_all(const std::vector<ImuSample>& samples, const IncrementOptions& options);

}  // namespace pednav::ins
