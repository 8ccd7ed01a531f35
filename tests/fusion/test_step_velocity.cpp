// SPDX-License-Identifier: BSD-2-Clause
// Step-velocity aiding (fusion/step_velocity.*, seed 000): the inverted-pendulum step length, the analytic Jacobian
// of the along/cross-track/vertical average-velocity measurement against central differences through the error-state
// boxplus (v + δv, exp([φ×]) R) at several attitudes, and the step segmentation of StepTracker.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/stance_updates.hpp"
#include "fusion/step_velocity.hpp"
#include "ins/alignment.hpp"
#include "tests/support/numdiff.hpp"

namespace pednav::fusion {
namespace {

constexpr double kStepLengthTol_m = 1e-9;
constexpr double kJacobianTol = 1e-6;      // [m/s per m/s] and [m/s per rad]
constexpr double kNumDiffStep = 1e-6;      // [m/s], [rad]

TEST(StepVelocity, InvertedPendulumStepLength) {
  // Seed 000's test gait: l = 0.7 m, φ_min = 60 deg: ΔL = 2 l cos φ_min = 0.7 m with h = l (1 − sin φ_min).
  const double l = 0.7, h = l * (1.0 - std::sin(60.0 * kDegToRad));
  EXPECT_NEAR(inverted_pendulum_step_length_m(l, h), 0.7, kStepLengthTol_m);
  EXPECT_EQ(inverted_pendulum_step_length_m(l, 0.0), 0.0);
  EXPECT_EQ(inverted_pendulum_step_length_m(l, -0.1), 0.0);
  EXPECT_NEAR(inverted_pendulum_step_length_m(l, 0.9), 1.4, kStepLengthTol_m);  // capped at 2 l
}

TEST(StepVelocity, JacobianMatchesNumericalDifferentiation) {
  const Geodetic llh{47.3 * kDegToRad, 8.5 * kDegToRad, 500.0};
  const Eigen::Vector3d p_e = ecef_from_geodetic(llh);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  struct Case {
    double roll, pitch, yaw;
    Eigen::Vector3d v_n;
  };
  const Case cases[] = {{0.0, 0.0, 0.0, {1.2, 0.1, 0.0}},
                        {0.05, -0.1, 2.0, {-0.6, 1.1, 0.05}},
                        {-0.3, 0.6, -2.9, {0.3, -1.4, -0.2}},
                        {0.0, 0.0, 3.14159, {-1.0, 0.0, 0.0}}};
  for (const Case& c : cases) {
    ins::NavState nav = ins::nav_state_at_rest(GpsTime::from_week_tow(2300, 10.0), p_e, c.roll, c.pitch, c.yaw);
    StepMeasurement m;
    m.model_speed_mps = 1.3;
    m.mean_v_e = Ren * c.v_n;
    const StepVelocityRows rows = step_velocity_rows(nav, m, StepVelocityOptions{});
    const Eigen::Matrix3d R = nav.R_e_b();
    auto f = [&](const Eigen::VectorXd& dx) -> Eigen::VectorXd {
      // h(x̂ ⊞ δx): v̄ + δv, exp([φ×]) R̂ (docs/error_state.md).
      return step_velocity_prediction(m.mean_v_e + dx.head<3>(), so3_exp(dx.tail<3>()) * R, p_e);
    };
    const Eigen::MatrixXd J = test::numerical_jacobian(f, Eigen::VectorXd::Zero(6), kNumDiffStep);
    EXPECT_LT((J - rows.J_dv_phi).cwiseAbs().maxCoeff(), kJacobianTol) << "rpy " << c.roll << " " << c.pitch << " "
                                                                       << c.yaw << "\nnum\n" << J << "\nana\n"
                                                                       << rows.J_dv_phi;
    // Residual = z − h: along = model speed − forward component, cross = − sideways component.
    const Eigen::Vector3d pred = step_velocity_prediction(m.mean_v_e, R, p_e);
    EXPECT_NEAR(rows.residual.x(), 1.3 - pred.x(), 1e-12);
    EXPECT_NEAR(rows.residual.y(), -pred.y(), 1e-12);
    EXPECT_NEAR(rows.residual.z(), -pred.z(), 1e-12);
  }
  // Heading 0, pitch 0: forward = north, the cross axis points east (down × north).
  const ins::NavState nav = ins::nav_state_at_rest(GpsTime::from_week_tow(2300, 10.0), p_e, 0.0, 0.0, 0.0);
  const Eigen::Vector3d pred = step_velocity_prediction(Ren * Eigen::Vector3d(1.0, 0.5, -0.2), nav.R_e_b(), p_e);
  EXPECT_NEAR(pred.x(), 1.0, 1e-9);
  EXPECT_NEAR(pred.y(), 0.5, 1e-9);
  EXPECT_NEAR(pred.z(), 0.2, 1e-9);
}

// The hand-held non-holonomic constraint (docs/fusion.md eq. 8.4): h(x) = the cross and up components of the current
// velocity, its Jacobian against central differences through the boxplus, its residual 0 − h and its noise.
TEST(HandNhc, JacobianMatchesNumericalDifferentiation) {
  const Geodetic llh{51.08 * kDegToRad, -114.13 * kDegToRad, 1050.0};
  const Eigen::Vector3d p_e = ecef_from_geodetic(llh);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  for (const auto& [rpy, v_n] : {std::pair{Eigen::Vector3d(0.03, -0.05, 0.7), Eigen::Vector3d(1.1, 0.9, 0.02)},
                                 std::pair{Eigen::Vector3d(-0.2, 0.3, -2.5), Eigen::Vector3d(-1.2, -0.4, -0.1)}}) {
    ins::NavState nav = ins::nav_state_at_rest(GpsTime::from_week_tow(2300, 10.0), p_e, rpy.x(), rpy.y(), rpy.z());
    nav.v_eb_e = Ren * v_n;
    const HandNhcRows rows = hand_nhc_rows(nav, 0.2, 0.3);
    const Eigen::Matrix3d R = nav.R_e_b();
    auto f = [&](const Eigen::VectorXd& dx) -> Eigen::VectorXd {
      return step_velocity_prediction(nav.v_eb_e + dx.head<3>(), so3_exp(dx.tail<3>()) * R, p_e).tail<2>();
    };
    const Eigen::MatrixXd J = test::numerical_jacobian(f, Eigen::VectorXd::Zero(6), kNumDiffStep);
    EXPECT_LT((J - rows.J_dv_phi).cwiseAbs().maxCoeff(), kJacobianTol) << "num\n" << J << "\nana\n" << rows.J_dv_phi;
    const Eigen::Vector3d pred = step_velocity_prediction(nav.v_eb_e, R, p_e);
    EXPECT_NEAR(rows.residual.x(), -pred.y(), 1e-12);
    EXPECT_NEAR(rows.residual.y(), -pred.z(), 1e-12);
    EXPECT_DOUBLE_EQ(rows.cov_meas(0, 0), 0.04);
    EXPECT_DOUBLE_EQ(rows.cov_meas(1, 1), 0.09);
    EXPECT_DOUBLE_EQ(rows.cov_meas(0, 1), 0.0);
  }
}

TEST(StepVelocity, TrackerSegmentsStepsAtStanceOnsets) {
  // A foot that rises 0.1 m and moves north at 1.4 m/s on average over 1 s cycles (30 % stance), 20 Hz epochs.
  const Geodetic llh{47.3 * kDegToRad, 8.5 * kDegToRad, 500.0};
  const Eigen::Vector3d p_e = ecef_from_geodetic(llh);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  StepVelocityOptions o;
  o.leg_length_m = 0.7;
  StepTracker tracker(o);
  const double dt = 0.05, swing = 0.7;
  int steps = 0;
  Eigen::Vector3d sum_v_dt = Eigen::Vector3d::Zero();  // expected: the same epoch sum the tracker uses
  for (int k = 0; k <= 200; ++k) {
    const double t = 1.0 + k * dt;
    const bool stance = (k % 20) < 6;  // 1 s cycle, 30 % stance
    Eigen::Vector3d v_n = Eigen::Vector3d::Zero();
    if (!stance) {
      const double s = ((k % 20) - 6 + 1) * dt / swing;   // 0..1 over the swing
      v_n.x() = 1.4 / swing * 2.0 * std::sin(M_PI * s) * std::sin(M_PI * s);
      v_n.z() = -0.1 * M_PI / swing * std::sin(2.0 * M_PI * s);  // up 0.1 m and back down
    }
    ins::NavState nav = ins::nav_state_at_rest(GpsTime::from_week_tow(2300, t), p_e, 0.0, 0.0, 0.0);
    nav.v_eb_e = Ren * v_n;
    const bool onset = (k % 20) == 0;
    if (auto m = tracker.push(nav, dt, stance)) {
      ASSERT_TRUE(onset);
      ++steps;
      EXPECT_NEAR(m->duration_s, 1.0, 1e-6);
      const Eigen::Vector3d mv_n = Ren.transpose() * m->mean_v_e;
      EXPECT_NEAR(mv_n.x(), sum_v_dt.x() / 1.0, 1e-9);
      EXPECT_NEAR(mv_n.x(), 1.4, 0.1);
      EXPECT_NEAR(mv_n.y(), 0.0, 1e-9);
      EXPECT_GT(m->rise_m, 0.02);  // half a step = stance + the first 0.2 s of the swing: the foot is rising
      EXPECT_NEAR(m->step_length_m, inverted_pendulum_step_length_m(0.7, m->rise_m), 1e-12);
    }
    if (onset) sum_v_dt.setZero();
    else sum_v_dt += v_n * dt;
  }
  EXPECT_GE(steps, 8);
}

}  // namespace
}  // namespace pednav::fusion
