// SPDX-License-Identifier: BSD-2-Clause
// Stride-average velocity of the IMU foot: the predicted velocity of a body-worn GNSS antenna (docs/fusion.md §13).
//
// A foot-mounted IMU stands still for a third of each gait cycle and swings at 1.5–2.5× the walking speed for the
// rest, while the antenna on the walker's body moves at the walking speed. Predicting the antenna's Doppler from the
// foot's instantaneous velocity is therefore biased by phase: in swing the Doppler "says" slower, in stance faster,
// and because the Doppler update during swing shortens the stride being integrated, the forward solution lags the
// walker along-track (measured: −0.26 m mean on forest_walk with error-free IMU data; −0.06 m without Doppler).
// The walking velocity is instead the foot's mean velocity over the last gait cycle,
//   v̄(t) = (D(t) − D(t − T_c)) / T_c,                                                                  (13.1)
// with D the cumulative mechanized displacement (the INS increments, without the filter's position corrections) and
// T_c the duration of the last complete cycle (stance onset to stance onset). Its error is dominated by the heading
// error, which rotates the whole INS stride: δv̄ = φ × v̄ = −[v̄×] φ (13.2); the current velocity error is reset at
// every ZUPT and is not in it. No file I/O, no logging, no heap allocation after construction.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>

namespace pednav::fusion {

struct StrideVelocityOptions {
  double min_cycle_s = 0.5;      ///< shorter intervals between stance onsets are not gait cycles [s]
  double max_cycle_s = 3.0;      ///< longer ones (standing, turning in place) are not gait cycles [s]
  double default_cycle_s = 1.2;  ///< window before the first complete cycle [s]
};

/// ∂v̄_true/∂φ of eq. 13.2 at the estimate v̄ (ECEF): −[v̄×] (v̄_true = exp([φ×]) v̄ to first order).
Eigen::Matrix3d stride_velocity_attitude_jacobian(const Eigen::Vector3d& v_bar_e);

class StrideVelocity {
 public:
  explicit StrideVelocity(StrideVelocityOptions o = {}) : o_(o) {}
  /// One mechanization step ending at t_ns [ns]: its mechanized displacement dp_e [m] (ECEF) and whether the
  /// detector flags stance at its end.
  void push(int64_t t_ns, const Eigen::Vector3d& dp_e, bool stance);
  /// v̄ at the last pushed step (eq. 13.1) [m/s], or nothing while the history is shorter than the window.
  std::optional<Eigen::Vector3d> velocity_e() const;
  /// The window T_c in use [s].
  double cycle_s() const { return cycle_s_; }
  void reset();

 private:
  struct Entry {
    int64_t t_ns = 0;
    Eigen::Vector3d d_e = Eigen::Vector3d::Zero();
  };
  static constexpr int kCapacity = 1024;  // 10 s at a 100 Hz mechanization, 51 s at 20 Hz
  StrideVelocityOptions o_;
  std::array<Entry, kCapacity> ring_{};
  int head_ = -1;  // index of the newest entry
  int size_ = 0;
  Eigen::Vector3d d_e_ = Eigen::Vector3d::Zero();
  bool prev_stance_ = false;
  std::optional<int64_t> last_onset_ns_;
  double cycle_s_ = 0.0;
};

}  // namespace pednav::fusion
