// SPDX-License-Identifier: BSD-2-Clause
#include <gtest/gtest.h>

#include <random>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"

namespace pednav {
namespace {

constexpr double kTolRot = 1e-12;

std::vector<Eigen::Vector3d> test_vectors() {
  std::vector<Eigen::Vector3d> v{Eigen::Vector3d::Zero(), Eigen::Vector3d(1e-8, 0, 0),
                                 Eigen::Vector3d(0, 1e-8, -1e-8), Eigen::Vector3d(0.3, -0.2, 0.1),
                                 Eigen::Vector3d(kPi - 1e-7, 0, 0), Eigen::Vector3d(0, 0, kPi - 1e-9).normalized() * (kPi - 1e-6)};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), a(0.0, kPi - 1e-3);
  for (int i = 0; i < 200; ++i) v.push_back(Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized() * a(rng));
  return v;
}

TEST(Rotation, ExpLogRoundTrip) {
  for (const auto& phi : test_vectors()) {
    const Eigen::Matrix3d R = so3_exp(phi);
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-13);
    EXPECT_LT((so3_log(R) - phi).norm(), 1e-9 * std::max(1.0, phi.norm())) << phi.transpose();
    EXPECT_LT((quat_exp(phi).toRotationMatrix() - R).norm(), kTolRot);
    EXPECT_LT((quat_log(quat_exp(phi)) - phi).norm(), 1e-12) << phi.transpose();
  }
}

TEST(Rotation, ExpMatchesAngleAxis) {
  const Eigen::Vector3d phi(0.4, -1.1, 0.7);
  const Eigen::Matrix3d ref = Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix();
  EXPECT_LT((so3_exp(phi) - ref).norm(), kTolRot);
}

TEST(Rotation, LogNearPiHasAnglePi) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(kPi, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  EXPECT_NEAR(so3_log(R).norm(), kPi, 1e-9);
}

TEST(Rotation, SkewIsCrossProduct) {
  const Eigen::Vector3d a(1, -2, 3), b(0.5, 4, -1);
  EXPECT_LT((skew(a) * b - a.cross(b)).norm(), 1e-15);
}

TEST(Rotation, RightJacobianMatchesFiniteDifference) {
  // exp(phi + d) ~= exp(phi) exp(Jr(phi) d)
  for (const Eigen::Vector3d& phi : {Eigen::Vector3d(0.2, -0.4, 0.9), Eigen::Vector3d(1e-7, 0, 0)}) {
    const Eigen::Vector3d d(1e-6, -2e-6, 0.5e-6);
    const Eigen::Vector3d lhs = so3_log(so3_exp(phi).transpose() * so3_exp(phi + d));
    EXPECT_LT((lhs - so3_right_jacobian(phi) * d).norm(), 1e-11);
  }
}

TEST(Rotation, EulerRoundTripAndConvention) {
  for (double r : {-2.5, -0.3, 0.0, 1e-8, 0.7, 3.0}) {
    for (double p : {-1.5, -0.4, 0.0, 1e-8, 1.2}) {
      for (double y : {-3.1, -1.0, 0.0, 0.5, 3.1}) {
        const Eigen::Vector3d e = euler_from_R_n_b(R_n_b_from_euler(r, p, y));
        EXPECT_LT((R_n_b_from_euler(e.x(), e.y(), e.z()) - R_n_b_from_euler(r, p, y)).norm(), 1e-12);
      }
    }
  }
  // Yaw 90 deg: body x axis points east.
  const Eigen::Vector3d x_n = R_n_b_from_euler(0, 0, kPi / 2) * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(x_n.y(), 1.0, 1e-15);
  // Pitch up: body x has a negative down component.
  EXPECT_LT((R_n_b_from_euler(0, 0.3, 0) * Eigen::Vector3d::UnitX()).z(), 0.0);
  // Gimbal lock keeps the rotation.
  const Eigen::Matrix3d gl = R_n_b_from_euler(0.2, kPi / 2, 0.5);
  const Eigen::Vector3d e = euler_from_R_n_b(gl);
  EXPECT_LT((R_n_b_from_euler(e.x(), e.y(), e.z()) - gl).norm(), 1e-7);
}

TEST(Rotation, OrthonormalizeAndWrap) {
  Eigen::Matrix3d m = so3_exp(Eigen::Vector3d(0.1, 0.2, 0.3));
  m(0, 1) += 1e-6;
  const Eigen::Matrix3d r = orthonormalize(m);
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(wrap_pi(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_pi(-kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_pi(-0.5), -0.5, 1e-15);
}

}  // namespace
}  // namespace pednav
