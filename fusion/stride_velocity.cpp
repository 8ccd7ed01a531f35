// SPDX-License-Identifier: BSD-2-Clause
#include "fusion/stride_velocity.hpp"

#include <cmath>

#include "core/rotation.hpp"

namespace pednav::fusion {

Eigen::Matrix3d stride_velocity_attitude_jacobian(const Eigen::Vector3d& v) { return -skew(v); }

void StrideVelocity::reset() {
  head_ = -1;
  size_ = 0;
  d_e_.setZero();
  prev_stance_ = false;
  last_onset_ns_.reset();
  cycle_s_ = 0.0;
}

void StrideVelocity::push(int64_t t_ns, const Eigen::Vector3d& dp_e, bool stance) {
  if (cycle_s_ <= 0.0) cycle_s_ = o_.default_cycle_s;
  if (stance && !prev_stance_) {
    if (last_onset_ns_) {
      const double c = static_cast<double>(t_ns - *last_onset_ns_) * 1e-9;
      if (c >= o_.min_cycle_s && c <= o_.max_cycle_s) cycle_s_ = c;
    }
    last_onset_ns_ = t_ns;
  }
  prev_stance_ = stance;
  d_e_ += dp_e;
  head_ = (head_ + 1) % kCapacity;
  ring_[static_cast<size_t>(head_)] = Entry{t_ns, d_e_};
  if (size_ < kCapacity) ++size_;
}

std::optional<Eigen::Vector3d> StrideVelocity::velocity_e() const {
  if (size_ < 2) return std::nullopt;
  const Entry& now = ring_[static_cast<size_t>(head_)];
  const int64_t target = now.t_ns - static_cast<int64_t>(std::llround(cycle_s_ * 1e9));
  // Newest to oldest: the first entry at or before the target, interpolated with its successor.
  for (int k = 1; k < size_; ++k) {
    const Entry& a = ring_[static_cast<size_t>((head_ - k + kCapacity) % kCapacity)];
    if (a.t_ns > target) continue;
    const Entry& b = ring_[static_cast<size_t>((head_ - k + 1 + kCapacity) % kCapacity)];
    const double span = static_cast<double>(b.t_ns - a.t_ns);
    const double w = span > 0.0 ? static_cast<double>(target - a.t_ns) / span : 0.0;
    const Eigen::Vector3d d_then = a.d_e + w * (b.d_e - a.d_e);
    return (now.d_e - d_then) / cycle_s_;
  }
  return std::nullopt;
}

}  // namespace pednav::fusion
