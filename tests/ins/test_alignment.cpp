// SPDX-License-Identifier: BSD-2-Clause
// Coarse levelling, stillness detection, heading.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "ins/alignment.hpp"
#include "motion.hpp"

namespace pednav::ins {
namespace {

using ::testing::HasSubstr;

constexpr double kTolAngle_rad = 1e-3;       // levelling with 0.01 m/s^2 noise over 2 s at 100 Hz
constexpr double kTolGyroBias_radps = 2e-3;  // 0.005 rad/s noise, 200 samples -> 3.5e-4 (1 sigma)

std::vector<ImuSample> still_log(const NavState& s, const Eigen::Vector3d& gyro_bias, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> ng(0.0, 0.005), na(0.0, 0.01);
  test::Kinematics k{s.p_eb_e, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), s.R_e_b(), Eigen::Vector3d::Zero()};
  const ImuSample exact = test::imu_from_kinematics(s.t, k);
  std::vector<ImuSample> out;
  for (int i = 0; i < n; ++i) {
    ImuSample x = exact;
    x.t = s.t.plus_ns(i * 10'000'000LL);
    x.omega_ib_b += gyro_bias + Eigen::Vector3d(ng(rng), ng(rng), ng(rng));
    x.f_ib_b += Eigen::Vector3d(na(rng), na(rng), na(rng));
    out.push_back(x);
  }
  return out;
}

TEST(Alignment, LevellingRecoversRollPitchAndGyroBias) {
  const NavState truth = test::nav_state_from_ll(GpsTime(), 53.3, -9.0, 20.0, 0.2, -0.35, 1.1);
  const Eigen::Vector3d bias(0.01, -0.02, 0.015);
  const auto log = still_log(truth, bias, 200, 42);
  auto lv = coarse_level(log, truth.p_eb_e, 1.1);
  ASSERT_TRUE(lv) << lv.error().message;
  EXPECT_NEAR(lv->roll, 0.2, kTolAngle_rad);
  EXPECT_NEAR(lv->pitch, -0.35, kTolAngle_rad);
  EXPECT_LT((lv->gyro_bias_b - bias).norm(), kTolGyroBias_radps);
  // The state at rest from the levelled roll and pitch and the true heading.
  const NavState s = nav_state_at_rest(GpsTime(), truth.p_eb_e, lv->roll, lv->pitch, 1.1);
  EXPECT_LT(so3_log(s.R_e_b().transpose() * truth.R_e_b()).norm(), 2 * kTolAngle_rad);
}

TEST(Alignment, MovingOrWrongUnitsAreRejectedWithReason) {
  const NavState truth = test::nav_state_from_ll(GpsTime(), 45.0, 7.0, 0.0, 0.0, 0.0, 0.0);
  auto log = still_log(truth, Eigen::Vector3d::Zero(), 200, 7);
  for (size_t i = 100; i < log.size(); ++i) log[i].omega_ib_b.x() += 0.5;  // starts rotating at 1 s
  auto lv = coarse_level(log, truth.p_eb_e);
  ASSERT_FALSE(lv);
  EXPECT_THAT(lv.error().message, HasSubstr("not still: gyro standard deviation"));
  auto g_units = still_log(truth, Eigen::Vector3d::Zero(), 200, 8);
  for (auto& x : g_units) x.f_ib_b /= 9.80665;  // accelerometer left in g
  auto bad = coarse_level(g_units, truth.p_eb_e);
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("is not local gravity"));
}

// A consumer accelerometer's zero-g offset (tens of mg, ~100 mg on some axes) is not a wrong unit: 1.0 m/s² along the
// vertical levels (the old 0.5 m/s² tolerance refused it and the run started without a levelled attitude), 2.0 m/s²
// is refused with the unit message (StillnessOptions::max_gravity_error_mps2 = 1.5).
TEST(Alignment, AConsumerAccelerometerOffsetLevelsAndTwoMetresPerSecondSquaredDoNot) {
  const NavState truth = test::nav_state_from_ll(GpsTime(), 45.0, 7.0, 0.0, 0.0, 0.0, 0.0);
  for (const double offset_mps2 : {1.0, 2.0}) {
    auto log = still_log(truth, Eigen::Vector3d::Zero(), 200, 9);
    for (auto& x : log) x.f_ib_b.z() -= offset_mps2;  // body z down: f_z = -g - offset
    auto lv = coarse_level(log, truth.p_eb_e);
    if (offset_mps2 < StillnessOptions{}.max_gravity_error_mps2) {
      ASSERT_TRUE(lv) << lv.error().message;
      EXPECT_NEAR(lv->roll, 0.0, kTolAngle_rad);
      EXPECT_NEAR(lv->pitch, 0.0, kTolAngle_rad);
    } else {
      ASSERT_FALSE(lv);
      EXPECT_THAT(lv.error().message, HasSubstr("is not local gravity"));
    }
  }
}

// Eq. 6.1 of docs/ins.md: d² of a still window's bias estimate against the turn-on prior; a window that rolls at
// 1 deg/s for its last second is far outside a 0.04 deg/s prior, a static one with a 1-sigma bias is not.
TEST(Alignment, StillWindowGyroBiasIsCheckedAgainstTheTurnOnPrior) {
  Levelling lv;
  lv.duration_s = 4.0;
  lv.gyro_bias_b = Eigen::Vector3d(3e-4, -4e-4, 0.0);                // |b| = 5e-4 rad/s
  EXPECT_NEAR(still_gyro_bias_d2(lv, 5e-4, 0.0), 1.0, 1e-12);         // |b|² / σ_b0²
  EXPECT_NEAR(still_gyro_bias_d2(lv, 5e-4, 1e-3), 0.5, 1e-12);        // + ARW²/T = 2.5e-7 rad²/s²
  const NavState truth = test::nav_state_from_ll(GpsTime(), 45.0, 7.0, 0.0, 0.0, 0.0, 0.0);
  auto log = still_log(truth, Eigen::Vector3d(1e-4, 0.0, -2e-4), 300, 9);  // 3 s at 100 Hz, noise 0.005 rad/s
  auto still = coarse_level(log, truth.p_eb_e);
  ASSERT_TRUE(still) << still.error().message;
  constexpr double kGyroBiasInitial_radps = 0.04 * kDegToRad;  // gx5_25 turn-on σ (7e-4 rad/s)
  constexpr double kNoiseArw = 0.005 * 0.1;                    // 0.005 rad/s per 10-ms sample as a density
  const double d2_still = still_gyro_bias_d2(*still, kGyroBiasInitial_radps, kNoiseArw);
  for (size_t i = 200; i < log.size(); ++i) log[i].omega_ib_b.z() += 1.0 * kDegToRad;  // rolls during its last second
  auto rolling = coarse_level(log, truth.p_eb_e);
  ASSERT_TRUE(rolling) << rolling.error().message;  // passes the stillness check: 1 deg/s is below its noise bound
  const double d2_rolling = still_gyro_bias_d2(*rolling, kGyroBiasInitial_radps, kNoiseArw);
  EXPECT_LT(d2_still, 16.27);   // χ²(3) at 0.999
  EXPECT_GT(d2_rolling, 16.27);
}

TEST(Alignment, MagnetometerHeading) {
  constexpr double kTol_rad = 1e-9;
  // Field pointing north and down (inclination 60 deg); body yawed by 0.7 rad, rolled and pitched.
  const Eigen::Vector3d m_n(std::cos(1.047), 0.0, std::sin(1.047));
  for (double yaw : {0.7, -2.5, 3.0}) {
    const Eigen::Matrix3d R_n_b = R_n_b_from_euler(0.1, -0.2, yaw);
    const Eigen::Vector3d m_b = R_n_b.transpose() * m_n;
    EXPECT_NEAR(wrap_pi(heading_from_magnetometer(m_b, 0.1, -0.2, 0.0) - yaw), 0.0, kTol_rad);
  }
}

}  // namespace
}  // namespace pednav::ins
