// SPDX-License-Identifier: BSD-2-Clause
// ZUPT measurement Jacobians (docs/fusion.md §5) against numerical differentiation through the error state's
// boxplus (docs/error_state.md §1: x_true = x_est ⊞ δx, R_true = exp([φ×]) R_est, δx = true − est).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "core/rotation.hpp"
#include "fusion/engine.hpp"
#include "fusion/stance_updates.hpp"
#include "ins/error_state.hpp"
#include "tests/support/numdiff.hpp"

namespace pednav {
namespace {

constexpr double kStep = 1e-6;          // central-difference step on δv [m/s] and φ [rad]
constexpr double kJacobianTol = 1e-7;   // absolute tolerance on Jacobian entries [m/s per unit]
constexpr int kTrials = 20;

// A random estimated state: ECEF position near the Earth's surface, foot-like velocity (|v| up to a few m/s),
// random attitude.
ins::InsState random_state(std::mt19937_64& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  ins::InsState x;
  x.nav.p_eb_e = Eigen::Vector3d(n01(rng), n01(rng), n01(rng)).normalized() * 6.37e6;
  x.nav.v_eb_e = 2.0 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
  x.nav.q_e_b = quat_exp(Eigen::Vector3d(n01(rng), n01(rng), n01(rng)));
  return x;
}

// Error-state vector with only the velocity (δv) and attitude (φ) blocks set from e = [δv; φ].
Eigen::VectorXd error_state(const ins::ErrorStateLayout& layout, const Eigen::VectorXd& e) {
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(layout.dim());
  dx.segment<3>(ins::kVel.offset) = e.head<3>();
  dx.segment<3>(ins::kAtt.offset) = e.tail<3>();
  return dx;
}

// The dynamic velocity error (seed 001 eq. 5 in our sign): the velocity error minus the part explained by rotating
// the estimated velocity with the attitude error, δv_dyn = v_true − exp([φ×]) v̂ = v_true − R_true R̂ᵀ v̂.
Eigen::VectorXd dynamic_velocity_error(const ins::InsState& est, const ins::ErrorStateLayout& layout,
                                       const Eigen::VectorXd& e) {
  const ins::InsState tr = ins::boxplus(est, error_state(layout, e), layout);
  return tr.nav.v_eb_e - tr.nav.R_e_b() * est.nav.R_e_b().transpose() * est.nav.v_eb_e;
}

// The full velocity error δv = v_true − v̂ (form F's measured quantity, seed 001 eq. 4).
Eigen::VectorXd full_velocity_error(const ins::InsState& est, const ins::ErrorStateLayout& layout,
                                    const Eigen::VectorXd& e) {
  const ins::InsState tr = ins::boxplus(est, error_state(layout, e), layout);
  return tr.nav.v_eb_e - est.nav.v_eb_e;
}

TEST(ZuptJacobian, FormDReproducesTheDynamicVelocityErrorThroughBoxplus) {
  std::mt19937_64 rng(5001);
  const ins::ErrorStateLayout layout;
  for (int k = 0; k < kTrials; ++k) {
    const ins::InsState est = random_state(rng);
    const auto f = [&](const Eigen::VectorXd& e) { return dynamic_velocity_error(est, layout, e); };
    const Eigen::MatrixXd J_num = test::numerical_jacobian(f, Eigen::VectorXd::Zero(6), kStep);
    const Eigen::Matrix<double, 3, 6> J = fusion::zupt_jacobian(est.nav.v_eb_e, fusion::ZuptForm::kDynamic);
    EXPECT_LT((J - J_num).cwiseAbs().maxCoeff(), kJacobianTol) << "trial " << k << "\nanalytic\n" << J
                                                               << "\nnumerical\n" << J_num;
    // The attitude block is +[v̂×] in our convention; the opposite sign (seed 001's β = −φ reading) is wrong.
    EXPECT_GT((J.rightCols<3>() + skew(est.nav.v_eb_e)).norm(), 1.0) << "trial " << k;
  }
}

TEST(ZuptJacobian, FormDLinearizationHoldsForSmallFiniteErrors) {
  // For a small but finite δx (0.01 m/s, 1 mrad) the linear model H_D δx predicts δv_dyn to second order.
  constexpr double kSecondOrderTol = 5e-5;  // |δv_dyn − H δx| [m/s] for |φ| ~ 1e-3 rad, |v̂| ~ 3 m/s
  std::mt19937_64 rng(5002);
  std::normal_distribution<double> n01(0.0, 1.0);
  const ins::ErrorStateLayout layout;
  for (int k = 0; k < kTrials; ++k) {
    const ins::InsState est = random_state(rng);
    Eigen::VectorXd e(6);
    e << 0.01 * n01(rng), 0.01 * n01(rng), 0.01 * n01(rng), 1e-3 * n01(rng), 1e-3 * n01(rng), 1e-3 * n01(rng);
    const Eigen::Vector3d predicted = fusion::zupt_jacobian(est.nav.v_eb_e, fusion::ZuptForm::kDynamic) * e;
    const Eigen::VectorXd actual = dynamic_velocity_error(est, layout, e);
    EXPECT_LT((predicted - actual).norm(), kSecondOrderTol) << "trial " << k;
    // Form F's H misses the attitude part by |v̂ × φ| ~ mm/s: far above the second-order residual.
    const Eigen::Vector3d predicted_f = fusion::zupt_jacobian(est.nav.v_eb_e, fusion::ZuptForm::kFull) * e;
    EXPECT_GT((predicted_f - actual).norm(), kSecondOrderTol) << "trial " << k;
  }
}

TEST(ZuptJacobian, FormFIsTheFullVelocityError) {
  std::mt19937_64 rng(5003);
  const ins::ErrorStateLayout layout;
  for (int k = 0; k < kTrials; ++k) {
    const ins::InsState est = random_state(rng);
    const Eigen::Matrix<double, 3, 6> J = fusion::zupt_jacobian(est.nav.v_eb_e, fusion::ZuptForm::kFull);
    Eigen::Matrix<double, 3, 6> expected = Eigen::Matrix<double, 3, 6>::Zero();
    expected.leftCols<3>().setIdentity();
    EXPECT_EQ(J, expected);
    const auto f = [&](const Eigen::VectorXd& e) { return full_velocity_error(est, layout, e); };
    const Eigen::MatrixXd J_num = test::numerical_jacobian(f, Eigen::VectorXd::Zero(6), kStep);
    EXPECT_LT((J - J_num).cwiseAbs().maxCoeff(), kJacobianTol) << "trial " << k;
  }
}

TEST(ZuptJacobian, FormsAgreeAtZeroVelocity) {
  // At v̂ = 0 the two forms coincide (seed 001: the difference is v'×β).
  EXPECT_EQ(fusion::zupt_jacobian(Eigen::Vector3d::Zero(), fusion::ZuptForm::kDynamic),
            fusion::zupt_jacobian(Eigen::Vector3d::Zero(), fusion::ZuptForm::kFull));
}

}  // namespace
}  // namespace pednav
