// SPDX-License-Identifier: BSD-2-Clause
// The stride-average foot velocity that the Doppler rows predict for a body-worn antenna (fusion/stride_velocity.hpp,
// docs/fusion.md §13): the window, the cycle from the stance onsets, and the attitude Jacobian (eq. 13.2) against
// numerical differentiation.
#include "fusion/stride_velocity.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

namespace pednav::fusion {
namespace {

constexpr int64_t kStepNs = 50'000'000;  // 20 Hz mechanization
constexpr double kStepS = 0.05;

// The swing profile of the simulator's foot, σ(s) = 35s⁴ − 84s⁵ + 70s⁶ − 20s⁷ (docs/sim.md §2).
double swing_profile(double s) { return s * s * s * s * (35.0 - 84.0 * s + 70.0 * s * s - 20.0 * s * s * s); }

// A foot that stands for `stance` steps and swings for `swing` steps per cycle, moving `stride` along `dir` in each
// swing with swing_profile. Pushes `cycles` cycles and returns the largest instantaneous foot speed seen.
double walk(StrideVelocity& sv, int64_t& t_ns, int cycles, int stance, int swing, double stride,
            const Eigen::Vector3d& dir = Eigen::Vector3d::UnitX()) {
  double vmax = 0.0;
  for (int c = 0; c < cycles; ++c) {
    for (int k = 0; k < stance; ++k) sv.push(t_ns += kStepNs, Eigen::Vector3d::Zero(), true);
    for (int k = 0; k < swing; ++k) {
      const double a = swing_profile(static_cast<double>(k) / swing);
      const double b = swing_profile(static_cast<double>(k + 1) / swing);
      vmax = std::max(vmax, stride * (b - a) / kStepS);
      sv.push(t_ns += kStepNs, dir * stride * (b - a), false);
    }
  }
  return vmax;
}

TEST(StrideVelocity, WalkingFootGivesTheWalkingSpeedNotTheFootSpeed) {
  // forest_walk's gait: cycle 1.25 s (25 steps), stance 30 %, stride 1.364 m → 1.091 m/s walking speed.
  StrideVelocity sv;
  int64_t t = 0;
  const double vmax = walk(sv, t, 3, 8, 17, 1.364);
  EXPECT_NEAR(sv.cycle_s(), 1.25, 1e-9);
  EXPECT_GT(vmax, 2.0);  // the foot itself swings at twice the walking speed
  // One more cycle of the same profile, one step at a time: at every phase the window holds exactly one stride.
  std::vector<Eigen::Vector3d> steps;
  std::vector<bool> stance;
  for (int k = 0; k < 8; ++k) steps.push_back(Eigen::Vector3d::Zero()), stance.push_back(true);
  for (int k = 0; k < 17; ++k) {
    steps.push_back(Eigen::Vector3d::UnitX() * 1.364 * (swing_profile((k + 1) / 17.0) - swing_profile(k / 17.0)));
    stance.push_back(false);
  }
  for (size_t k = 0; k < steps.size(); ++k) {
    sv.push(t += kStepNs, steps[k], stance[k]);
    const std::optional<Eigen::Vector3d> v = sv.velocity_e();
    ASSERT_TRUE(v.has_value());
    EXPECT_NEAR(v->x(), 1.364 / 1.25, 1e-9) << "phase step " << k;
    EXPECT_NEAR(v->tail<2>().norm(), 0.0, 1e-12);
  }
}

TEST(StrideVelocity, NothingUntilTheHistorySpansTheWindow) {
  StrideVelocity sv;  // default window 1.2 s before the first complete cycle
  int64_t t = 0;
  EXPECT_FALSE(sv.velocity_e().has_value());
  for (int k = 0; k < 23; ++k) sv.push(t += kStepNs, Eigen::Vector3d(0.05, 0, 0), false);  // 1.1 s of history
  EXPECT_FALSE(sv.velocity_e().has_value());
  for (int k = 0; k < 3; ++k) sv.push(t += kStepNs, Eigen::Vector3d(0.05, 0, 0), false);
  ASSERT_TRUE(sv.velocity_e().has_value());
  EXPECT_NEAR(sv.velocity_e()->x(), 1.0, 1e-12);
  EXPECT_NEAR(sv.cycle_s(), 1.2, 1e-12);
}

TEST(StrideVelocity, CycleFromStanceOnsetsIgnoresPausesAndShortFlickers) {
  StrideVelocity sv;
  int64_t t = 0;
  walk(sv, t, 3, 6, 16, 1.2);  // 22 steps = 1.1 s cycles
  EXPECT_NEAR(sv.cycle_s(), 1.1, 1e-9);
  for (int k = 0; k < 100; ++k) sv.push(t += kStepNs, Eigen::Vector3d::Zero(), true);  // a 5 s pause
  walk(sv, t, 1, 0, 16, 1.2);
  sv.push(t += kStepNs, Eigen::Vector3d::Zero(), true);  // onset after > max_cycle_s: not a cycle
  EXPECT_NEAR(sv.cycle_s(), 1.1, 1e-9);
  sv.push(t += kStepNs, Eigen::Vector3d::Zero(), false);
  sv.push(t += kStepNs, Eigen::Vector3d::Zero(), true);  // a 0.1 s flicker: shorter than min_cycle_s
  EXPECT_NEAR(sv.cycle_s(), 1.1, 1e-9);
  for (int k = 0; k < 40; ++k) sv.push(t += kStepNs, Eigen::Vector3d::Zero(), true);
  ASSERT_TRUE(sv.velocity_e().has_value());
  EXPECT_NEAR(sv.velocity_e()->norm(), 0.0, 1e-12);  // standing: the body stands too
}

TEST(StrideVelocity, RingBufferWrapsAroundAndResetForgets) {
  StrideVelocity sv;
  int64_t t = 0;
  const Eigen::Vector3d dir = Eigen::Vector3d(0.6, -0.8, 0.0);
  walk(sv, t, 250, 8, 17, 1.3, dir);  // 6250 steps, six times the ring's capacity
  ASSERT_TRUE(sv.velocity_e().has_value());
  EXPECT_NEAR((*sv.velocity_e() - dir * (1.3 / 1.25)).norm(), 0.0, 1e-9);
  sv.reset();
  EXPECT_FALSE(sv.velocity_e().has_value());
  EXPECT_EQ(sv.cycle_s(), 0.0);
}

// Eq. 13.2: an attitude error φ rotates the INS stride, v̄_true = exp([φ×]) v̄_est; the Jacobian is the derivative of
// that model at φ = 0, and the window of a walk whose every displacement is rotated gives the same first-order change.
TEST(StrideVelocity, AttitudeJacobianMatchesNumericalDifferentiation) {
  const Eigen::Vector3d v(0.9, -0.55, 0.07);
  const Eigen::Matrix3d J = stride_velocity_attitude_jacobian(v);
  constexpr double h = 1e-6;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(i) * h;
    const Eigen::Vector3d plus = Eigen::AngleAxisd(h, Eigen::Vector3d::Unit(i)) * v;
    const Eigen::Vector3d minus = Eigen::AngleAxisd(-h, Eigen::Vector3d::Unit(i)) * v;
    const Eigen::Vector3d num = (plus - minus) / (2.0 * h);
    EXPECT_NEAR((J.col(i) - num).norm(), 0.0, 1e-8) << "column " << i << " (e = " << e.transpose() << ")";
  }
  // Through the window: a walk along dir and the same walk with every displacement rotated by a small yaw φ_z.
  const Eigen::Vector3d dir = Eigen::Vector3d(0.8, 0.6, 0.0);
  const Eigen::Vector3d phi(0.0, 0.0, 2e-3);
  StrideVelocity a, b;
  int64_t ta = 0, tb = 0;
  walk(a, ta, 4, 8, 17, 1.364, dir);
  walk(b, tb, 4, 8, 17, 1.364, Eigen::AngleAxisd(phi.norm(), phi.normalized()) * dir);
  const Eigen::Vector3d dv = *b.velocity_e() - *a.velocity_e();
  const Eigen::Vector3d predicted = stride_velocity_attitude_jacobian(*a.velocity_e()) * phi;
  EXPECT_NEAR((dv - predicted).norm(), 0.0, 1e-3 * predicted.norm());  // second order in φ
}

}  // namespace
}  // namespace pednav::fusion
