// SPDX-License-Identifier: BSD-2-Clause
// Increment integration: grid alignment, interpolation, coning and sculling against analytic motions.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "ins/imu.hpp"

namespace pednav::ins {
namespace {

TEST(IncrementIntegrator, IntervalsLieOnTheGpsTimeGridForAnyRate) {
  // 200 Hz samples starting off-grid; 30 Hz mechanization (not a divisor of 200) and 200 Hz (= IMU rate).
  std::vector<ImuSample> s;
  for (int i = 0; i < 401; ++i) {
    ImuSample x;
    x.t = GpsTime::from_ns(1'234'567 + i * 5'000'000LL);
    x.omega_ib_b = Eigen::Vector3d(0.1, 0.0, 0.0);
    x.f_ib_b = Eigen::Vector3d(0.0, 0.0, -9.8);
    s.push_back(x);
  }
  for (double rate : {30.0, 200.0, 1000.0}) {
    const auto incs = integrate_all(s, {rate, true, true});
    ASSERT_FALSE(incs.empty());
    const int64_t period = std::llround(1e9 / rate);
    double total = 0.0;
    for (size_t i = 0; i < incs.size(); ++i) {
      EXPECT_EQ(incs[i].t1.ns() % period, 0) << rate;
      if (i > 0) {
        EXPECT_EQ(incs[i].t0, incs[i - 1].t1);
      }
      total += incs[i].alpha_b.x();
    }
    // Constant rate: the angle over all complete intervals equals rate * span.
    EXPECT_NEAR(total, 0.1 * (incs.back().t1 - incs.front().t0), 1e-12) << rate;
    EXPECT_NEAR(incs[1].dt_s, 1.0 / rate, 1e-9);
  }
}

// IncrementIntegrator::cut closes the interval at the last sample and keeps the grid: the next interval ends at the
// grid point the cut one would have reached, and the increments add up to those of the uncut integration.
TEST(IncrementIntegrator, CutKeepsTheGrid) {
  std::vector<ImuSample> s;
  for (int i = 0; i < 41; ++i) {
    ImuSample x;
    x.t = GpsTime::from_ns(2'500'000LL + i * 5'000'000LL);
    x.omega_ib_b = Eigen::Vector3d(0.3 + 0.01 * i, -0.2, 0.1);
    x.f_ib_b = Eigen::Vector3d(0.5, 0.0, -9.8 + 0.02 * i);
    s.push_back(x);
  }
  IncrementIntegrator whole({20.0, true, true}), cut({20.0, true, true});
  std::vector<ImuIncrement> a, b;
  for (const auto& x : s) whole.push(x, [&](const ImuIncrement& inc) { a.push_back(inc); });
  for (size_t i = 0; i < s.size(); ++i) {
    cut.push(s[i], [&](const ImuIncrement& inc) { b.push_back(inc); });
    ImuIncrement early;
    if (i == 13) {  // 67.5 ms: inside the interval (50, 100] ms
      ASSERT_TRUE(cut.cut(early));
      b.push_back(early);
      EXPECT_FALSE(cut.cut(early));  // nothing left to close at the same sample
    }
  }
  ASSERT_EQ(b.size(), a.size() + 1);
  EXPECT_EQ(b[1].t1.ns(), 67'500'000);
  EXPECT_EQ(b[2].t0.ns(), 67'500'000);
  EXPECT_EQ(b[2].t1.ns(), 100'000'000);  // the grid point the cut interval would have reached
  for (size_t i = 3; i < b.size(); ++i) EXPECT_EQ(b[i].t1, a[i - 1].t1);
  EXPECT_TRUE((b[1].alpha_b + b[2].alpha_b).isApprox(a[1].alpha_b, 1e-12));
  EXPECT_TRUE((b[1].upsilon_b + b[2].upsilon_b).isApprox(a[1].upsilon_b, 1e-12));
  EXPECT_EQ(b[1].samples + b[2].samples, a[1].samples);
}

// IncrementIntegrator::flush closes the trailing partial interval at the last sample (end of data): it starts where the
// last complete interval ended, holds exactly the samples after it, and with the complete intervals adds up to the
// whole log; an empty interval (nothing pushed, the last sample on a grid point, or flushed already) gives false.
TEST(IncrementIntegrator, FlushClosesThePartialIntervalAtTheLastSample) {
  IncrementIntegrator empty({20.0, true, true});
  ImuIncrement inc;
  EXPECT_FALSE(empty.flush(inc)) << "nothing pushed";
  std::vector<ImuSample> s;
  for (int i = 0; i < 38; ++i) {  // 200 Hz from 2.5 ms to 187.5 ms: intervals end at 50, 100, 150 ms, then 37.5 ms left
    ImuSample x;
    x.t = GpsTime::from_ns(2'500'000LL + i * 5'000'000LL);
    x.omega_ib_b = Eigen::Vector3d(0.3 + 0.01 * i, -0.2, 0.1);
    x.f_ib_b = Eigen::Vector3d(0.5, 0.0, -9.8 + 0.02 * i);
    s.push_back(x);
  }
  IncrementIntegrator integ({20.0, true, true});
  std::vector<ImuIncrement> incs;
  for (const auto& x : s) integ.push(x, [&](const ImuIncrement& i) { incs.push_back(i); });
  ASSERT_EQ(incs.size(), 3u);
  ASSERT_TRUE(integ.flush(inc));
  EXPECT_EQ(inc.t0, incs.back().t1);
  EXPECT_EQ(inc.t0.ns(), 150'000'000);
  EXPECT_EQ(inc.t1, s.back().t);
  EXPECT_NEAR(inc.dt_s, 0.0375, 1e-12);
  EXPECT_EQ(inc.samples, 8);  // sub-intervals 150-152.5 ms (from the interpolated grid point), then 7 of 5 ms
  EXPECT_EQ(inc.omega_end_b, s.back().omega_ib_b);
  EXPECT_EQ(inc.f_end_b, s.back().f_ib_b);
  // Rates linear between samples: the trapezoid sums over all intervals equal the trapezoid sum over the samples.
  Eigen::Vector3d alpha = inc.alpha_b, upsilon = inc.upsilon_b;
  for (const auto& i : incs) {
    alpha += i.alpha_b;
    upsilon += i.upsilon_b;
  }
  Eigen::Vector3d alpha_samples = Eigen::Vector3d::Zero(), upsilon_samples = Eigen::Vector3d::Zero();
  for (size_t k = 1; k < s.size(); ++k) {
    const double h = static_cast<double>(s[k].t.ns() - s[k - 1].t.ns()) * 1e-9;
    alpha_samples += 0.5 * h * (s[k - 1].omega_ib_b + s[k].omega_ib_b);
    upsilon_samples += 0.5 * h * (s[k - 1].f_ib_b + s[k].f_ib_b);
  }
  EXPECT_TRUE(alpha.isApprox(alpha_samples, 1e-12));
  EXPECT_TRUE(upsilon.isApprox(upsilon_samples, 1e-12));
  // The same increments as a fresh integrator started at the grid point (nothing left over from earlier intervals).
  IncrementIntegrator fresh({20.0, true, true});
  fresh.push(IncrementIntegrator::interpolate(s[29], s[30], inc.t0), [](const ImuIncrement&) {});
  for (size_t k = 30; k < s.size(); ++k) fresh.push(s[k], [](const ImuIncrement&) { ADD_FAILURE(); });
  ImuIncrement ref;
  ASSERT_TRUE(fresh.flush(ref));
  EXPECT_EQ(ref.samples, inc.samples);
  EXPECT_TRUE(inc.dtheta_b.isApprox(ref.dtheta_b, 1e-15));
  EXPECT_TRUE(inc.dv_b.isApprox(ref.dv_b, 1e-15));
  EXPECT_TRUE(inc.dp_b.isApprox(ref.dp_b, 1e-15));
  EXPECT_FALSE(integ.flush(inc)) << "flushed already";
  // On the grid: a log that ends exactly at an interval end leaves nothing to flush.
  IncrementIntegrator on_grid({20.0, true, true});
  for (size_t k = 0; k <= 29; ++k) on_grid.push(s[k], [](const ImuIncrement&) {});  // s[29] at 147.5 ms
  ImuSample at_end = s[29];
  at_end.t = GpsTime::from_ns(150'000'000);
  on_grid.push(at_end, [](const ImuIncrement&) {});
  EXPECT_FALSE(on_grid.flush(inc)) << "the last sample closed its interval";
}

// Classic coning: R_i_b(t) = Rz(Ωt) Rx(β) Rz(-Ωt); body rate ω_b = Ω (R^T e_z - e_z) (exact), so the
// attitude is known in closed form; the uncompensated algorithm drifts about the cone axis at
// ≈ Ω (1 - cos β) minus what the sum of plain increments captures (Savage 1998 Part 1).
TEST(IncrementIntegrator, ConingCompensationIsAtLeastTenTimesBetter) {
  constexpr double kMinImprovement = 10.0;  // issue 12
  const double Omega = 2.0 * kPi * 2.0, beta = 0.1, imu_rate = 200.0, mech_rate = 20.0, T = 10.0;
  auto R = [&](double t) {
    return Eigen::Matrix3d(Eigen::AngleAxisd(Omega * t, Eigen::Vector3d::UnitZ()) *
                           Eigen::AngleAxisd(beta, Eigen::Vector3d::UnitX()) *
                           Eigen::AngleAxisd(-Omega * t, Eigen::Vector3d::UnitZ()));
  };
  std::vector<ImuSample> s;
  for (int i = 0; i <= static_cast<int>(T * imu_rate); ++i) {
    const double t = i / imu_rate;
    ImuSample x;
    x.t = GpsTime::from_ns(std::llround(t * 1e9));
    x.omega_ib_b = Omega * (R(t).transpose() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ());
    s.push_back(x);
  }
  auto attitude_error = [&](bool coning) {
    Eigen::Quaterniond q(R(0.0));
    GpsTime end;
    for (const auto& inc : integrate_all(s, {mech_rate, coning, true})) {
      q = q * quat_exp(inc.dtheta_b);
      end = inc.t1;
    }
    return so3_log(R(end.seconds()).transpose() * q.toRotationMatrix()).norm();
  };
  const double with = attitude_error(true), without = attitude_error(false);
  std::printf("[coning 2 Hz, beta 0.1 rad, 10 s, IMU 200 Hz -> 20 Hz] error with %.3e rad, without %.3e rad (x%.0f)\n",
              with, without, without / with);
  EXPECT_GT(without, 1e-3);  // the test motion really cones
  EXPECT_LT(with * kMinImprovement, without);
  // Measured 2026-12-05: with 4.119e-4 rad, without 4.079e-2 rad (deterministic arithmetic): +30 % / −30 %.
  EXPECT_LT(with, 1.3 * 4.119e-4);
  EXPECT_GT(without, 4.079e-2 / 1.3);
}

// Sculling: rotation about z at Ω with a body specific force rotating in phase (classic sculling motion):
// ω_b = (0, 0, Ω), f_b = A (cos Ωt, -sin Ωt, 0)... chosen so that the inertial f is constant A e_x;
// the true inertial velocity change is A Δt e_x; without compensation it is wrong by O(ΩΔt) per interval.
TEST(IncrementIntegrator, RotationAndScullingCompensationAgainstAnalyticVelocity) {
  constexpr double kMinImprovement = 10.0;
  const double Omega = 3.0, A = 5.0, imu_rate = 400.0, mech_rate = 20.0, T = 5.0;
  std::vector<ImuSample> s;
  for (int i = 0; i <= static_cast<int>(T * imu_rate); ++i) {
    const double t = i / imu_rate;
    ImuSample x;
    x.t = GpsTime::from_ns(std::llround(t * 1e9));
    x.omega_ib_b = Eigen::Vector3d(0.0, 0.0, Omega);
    x.f_ib_b = A * Eigen::Vector3d(std::cos(Omega * t), -std::sin(Omega * t), 0.0);  // R_i_b^T (A e_x)
    s.push_back(x);
  }
  auto velocity_error = [&](bool sculling) {
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    double t = 0.0;
    for (const auto& inc : integrate_all(s, {mech_rate, true, sculling})) {
      v += q * inc.dv_b;
      q = q * quat_exp(inc.dtheta_b);
      t = inc.t1.seconds();
    }
    return (v - A * t * Eigen::Vector3d::UnitX()).norm();
  };
  const double with = velocity_error(true), without = velocity_error(false);
  std::printf("[rotation+sculling 5 s] velocity error with %.3e m/s, without %.3e m/s\n", with, without);
  EXPECT_LT(with * kMinImprovement, without);
  // Measured 2026-12-05: with 1.172e-4 m/s, without 1.874 m/s (deterministic arithmetic): +30 % / −30 %.
  EXPECT_LT(with, 1.3 * 1.172e-4);
  EXPECT_GT(without, 1.874 / 1.3);
}

}  // namespace
}  // namespace pednav::ins
