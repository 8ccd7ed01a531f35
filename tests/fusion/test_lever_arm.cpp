// SPDX-License-Identifier: BSD-2-Clause
// The foot-IMU -> antenna lever arm with a part fixed in the foot's heading frame (fusion/lever_arm.hpp,
// docs/fusion.md §14): its value at known headings, and its attitude Jacobian (eq. 14.2) against numerical
// differentiation through the error-state attitude perturbation, for level and strongly pitched feet.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/geodesy.hpp"
#include "fusion/lever_arm.hpp"

namespace pednav::fusion {
namespace {

// R_n_b from yaw, pitch, roll (NED, z-y-x).
Eigen::Matrix3d r_n_b(double yaw, double pitch, double roll) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

TEST(LeverArm, HeadingPartFollowsTheFootsHeadingNotItsPitch) {
  const Eigen::Matrix3d Ren = R_e_n(0.9, -2.0);
  const Eigen::Vector3d arm_n(0.0, 0.0, -1.5), arm_h(0.0, -0.1, 0.0);  // right foot: body 0.1 m to its left
  for (const double pitch : {0.0, 0.7, -1.0}) {
    // Walking east (yaw 90°): left of the foot is north.
    const LeverArm a = lever_arm_e(arm_n, arm_h, Ren, Ren * r_n_b(M_PI / 2, pitch, 0.1));
    const Eigen::Vector3d n = Ren.transpose() * a.arm_e;
    EXPECT_NEAR(n.x(), 0.1, 1e-12) << pitch;
    EXPECT_NEAR(n.y(), 0.0, 1e-12) << pitch;
    EXPECT_NEAR(n.z(), -1.5, 1e-12) << pitch;
  }
  // No heading part: the level arm alone and no attitude dependence.
  const LeverArm a = lever_arm_e(arm_n, Eigen::Vector3d::Zero(), Ren, Ren * r_n_b(0.3, 0.2, 0.0));
  EXPECT_TRUE((Ren.transpose() * a.arm_e - arm_n).norm() < 1e-12);
  EXPECT_TRUE(a.d_arm_d_phi_e.isZero());
}

TEST(LeverArm, AttitudeJacobianMatchesNumericalDifferentiation) {
  const Eigen::Matrix3d Ren = R_e_n(0.9, -2.0);
  const Eigen::Vector3d arm_n(0.02, 0.0, -1.55), arm_h(0.15, -0.1, 0.03);
  constexpr double kStep = 1e-6;
  int checked = 0;
  for (const double yaw : {0.0, 1.1, -2.5}) {
    for (const double pitch : {0.0, 0.5, -1.05}) {  // level, heel-off, 60° toe-down push-off
      const Eigen::Matrix3d Reb = Ren * r_n_b(yaw, pitch, 0.2);
      const LeverArm a = lever_arm_e(arm_n, arm_h, Ren, Reb);
      Eigen::Matrix3d J;
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d phi = Eigen::Vector3d::Zero();
        phi(k) = kStep;
        // True attitude = exp([φ×]) R_e_b (docs/error_state.md).
        const Eigen::Matrix3d plus = Eigen::AngleAxisd(kStep, phi.normalized()).toRotationMatrix() * Reb;
        const Eigen::Matrix3d minus = Eigen::AngleAxisd(-kStep, phi.normalized()).toRotationMatrix() * Reb;
        J.col(k) =
            (lever_arm_e(arm_n, arm_h, Ren, plus).arm_e - lever_arm_e(arm_n, arm_h, Ren, minus).arm_e) / (2.0 * kStep);
      }
      EXPECT_LT((J - a.d_arm_d_phi_e).cwiseAbs().maxCoeff(), 1e-8) << "yaw " << yaw << " pitch " << pitch << "\n"
                                                                   << J << "\n"
                                                                   << a.d_arm_d_phi_e;
      EXPECT_GT(a.d_arm_d_phi_e.norm(), 0.05);  // the arm does rotate: the comparison is not 0 = 0
      ++checked;
    }
  }
  EXPECT_EQ(checked, 9);
}

}  // namespace
}  // namespace pednav::fusion
