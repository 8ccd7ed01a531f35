// SPDX-License-Identifier: BSD-2-Clause
// The antenna states of the tight coupling with carrier (fusion/antenna_state.*, docs/carrier.md §10): the tie's
// Jacobian (eq. 10.2) against central differences through the error-state boxplus (p + δp, v + δv, exp([φ×]) R,
// antenna p_a + δp_a, v_a + δv_a, arm error b + δb) with and without a stride velocity, the samples the tie is
// applied at (mid-stance, every 10 s while standing), the white-acceleration prediction of the antenna block (eq.
// 10.1), and the consistency gate (eq. 10.4) that inflates a tie's noise when the foot and the antenna disagree beyond both σ's.
#include <gtest/gtest.h>

#include <cmath>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/antenna_state.hpp"
#include "fusion/error_state_filter.hpp"
#include "ins/alignment.hpp"
#include "ins/gravity.hpp"
#include "ins/imu_spec.hpp"
#include "tests/support/numdiff.hpp"

namespace pednav::fusion {
namespace {

constexpr double kJacobianTol = 1e-6;  // [m per m], [m per rad], [m/s per rad]
constexpr double kNumDiffStep = 1e-6;

TEST(AntennaTie, JacobianMatchesNumericalDifferentiation) {
  const Geodetic llh{53.28 * kDegToRad, -9.06 * kDegToRad, 20.0};
  const Eigen::Vector3d p_e = ecef_from_geodetic(llh);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  const Eigen::Vector3d arm_n(0.0, 0.0, -1.5), arm_h(0.0, -0.1, 0.0);
  const Eigen::Vector3d v_e = Ren * Eigen::Vector3d(0.8, 1.9, -0.2);
  const Eigen::Vector3d ant_p = p_e + Ren * Eigen::Vector3d(0.3, -0.2, -1.4), ant_v = Ren * Eigen::Vector3d(0.9, 0.7, 0.0);
  const Eigen::Matrix3d C = Eigen::Matrix3d::Identity() * 0.01;
  for (const bool with_stride : {true, false}) {
    for (const Eigen::Vector3d& rpy : {Eigen::Vector3d(0.05, 0.6, 1.1), Eigen::Vector3d(-0.1, -0.9, -2.6)}) {
      const Eigen::Matrix3d R = Ren * so3_exp(Eigen::Vector3d(0, 0, rpy.z())) * so3_exp(Eigen::Vector3d(0, rpy.y(), 0)) *
                                so3_exp(Eigen::Vector3d(rpy.x(), 0, 0));
      const std::optional<Eigen::Vector3d> vs =
          with_stride ? std::optional<Eigen::Vector3d>(Ren * Eigen::Vector3d(1.1, 0.6, 0.01)) : std::nullopt;
      const Eigen::Vector3d b(0.05, -0.03, 0.2);  // the arm's error estimate (heading frame)
      const AntennaTieRows t = antenna_tie_rows(p_e, v_e, lever_arm_e(arm_n, arm_h + b, Ren, R),
                                                arm_heading_axes_e(Ren, R), vs, ant_p, ant_v, C, C);
      // h(x) with the error applied: the stride velocity rotates with the attitude error (docs/fusion.md eq. 13.2).
      auto h = [&](const Eigen::VectorXd& dx) -> Eigen::VectorXd {
        const Eigen::Matrix3d Rt = so3_exp(dx.segment<3>(kTieFootAtt)) * R;
        const LeverArm arm = lever_arm_e(arm_n, arm_h + b + dx.segment<3>(kTieArmError), Ren, Rt);
        Eigen::VectorXd out(6);
        // the antenna-minus-foot difference first: differences of 6e6-m ECEF coordinates would cost the step's digits
        out.head<3>() = (ant_p - p_e) + dx.segment<3>(kTieAntPos) - dx.segment<3>(kTieFootPos) - arm.arm_e;
        const Eigen::Vector3d v_ref = vs ? Eigen::Vector3d(so3_exp(dx.segment<3>(kTieFootAtt)) * *vs)
                                         : Eigen::Vector3d(v_e + dx.segment<3>(kTieFootVel));
        out.tail<3>() = (ant_v + dx.segment<3>(kTieAntVel)) - v_ref;
        return out;
      };
      const Eigen::MatrixXd J = test::numerical_jacobian(h, Eigen::VectorXd::Zero(18), kNumDiffStep);
      EXPECT_LT((J - t.J).cwiseAbs().maxCoeff(), kJacobianTol) << "num\n" << J << "\nana\n" << t.J;
      const Eigen::VectorXd h0 = h(Eigen::VectorXd::Zero(18));
      EXPECT_LT((t.residual + h0).cwiseAbs().maxCoeff(), 1e-9);
      EXPECT_TRUE((t.cov_meas.topLeftCorner<3, 3>() - C).isZero());
      EXPECT_TRUE((t.cov_meas.block<3, 3>(0, 3)).isZero());
    }
  }
}

std::vector<ins::ImuSample> samples_at(double rate_hz, double span_s) {
  std::vector<ins::ImuSample> s;
  for (int i = 0; i < static_cast<int>(span_s * rate_hz); ++i) s.push_back({GpsTime::from_week_tow(2300, i / rate_hz)});
  return s;
}

TEST(AntennaTie, AtMidStanceAndEveryTenSecondsWhileStanding) {
  const auto imu = samples_at(100.0, 20.0);
  std::vector<ins::ZuptDecision> d(imu.size());
  for (size_t i = 100; i < 140; ++i) d[i].stance = true;    // a 0.4-s stance: its middle, sample 119
  for (size_t i = 300; i < 340; ++i) d[i].stance = true;    // another: 319
  for (size_t i = 500; i < 1900; ++i) d[i].stance = true;  // standing 5.0-18.99 s: 5.5 and 15.5 s (kStandingTieSpacingS)
  const std::vector<size_t> t = antenna_tie_samples(d, imu);
  ASSERT_EQ(t.size(), 4u);
  EXPECT_EQ(t[0], 119u);
  EXPECT_EQ(t[1], 319u);
  EXPECT_EQ(t[2], 550u);
  EXPECT_EQ(t[3], 1550u);
  // A stance ending less than 0.5 s after the next spacing point does not get it.
  for (size_t i = 1900; i < 1990; ++i) d[i].stance = true;  // now 5.0-19.89 s: still 5.5 and 15.5 s
  EXPECT_EQ(antenna_tie_samples(d, imu).size(), 4u);
  // No stance: no tie sample (the GNSS epochs tie the antenna then, fusion/forward_runner).
  EXPECT_TRUE(antenna_tie_samples(std::vector<ins::ZuptDecision>(imu.size()), imu).empty());
}

EngineOptions antenna_options() {
  EngineOptions o;
  o.mode = Mode::kTightlyCoupled;
  o.carrier = true;
  o.antenna_state = true;
  o.multipath_sigma_m = 0.0;
  o.spec = *ins::imu_spec_preset("crista");
  o.spec.gyro_g_sensitivity = 0.0;
  return o;
}

ins::NavState level_nav(const Eigen::Vector3d& p_e) {
  return ins::nav_state_at_rest(GpsTime::from_week_tow(2300, 10.0), p_e, 0.0, 0.0, 0.5);
}

TEST(AntennaState, WhiteAccelerationPrediction) {
  const EngineOptions o = antenna_options();
  ErrorStateFilter f(o, 1);
  ASSERT_TRUE(f.problem().empty()) << f.problem();
  ASSERT_TRUE(f.has_antenna());
  const Eigen::Vector3d p_e = ecef_from_geodetic(Geodetic{0.9, -0.2, 30.0});
  f.init(level_nav(p_e), ins::ImuErrors{}, 0.1);
  const Eigen::Vector3d v_a(0.5, -1.0, 0.25);
  f.init_antenna(p_e, v_a, Eigen::Matrix3d::Identity() * 1e-4, Eigen::Matrix3d::Identity() * 1e-6,
                 Eigen::Matrix3d::Identity() * 0.01);
  const int a = f.antenna_offset();
  // 1 s at 20 Hz of a foot at rest.
  const Eigen::Vector3d g_b = f.x().nav.R_e_b().transpose() * (-ins::gravity_ecef(p_e));
  for (int k = 0; k < 20; ++k) {
    ins::ImuIncrement inc;
    inc.t0 = f.x().nav.t;
    inc.dt_s = 0.05;
    inc.t1 = inc.t0.plus_s(inc.dt_s);
    inc.dv_b = inc.upsilon_b = g_b * inc.dt_s;
    inc.dp_b = 0.5 * inc.dv_b * inc.dt_s;
    inc.f_end_b = g_b;
    f.predict(inc);
  }
  EXPECT_LT((f.antenna_p_e() - (p_e + v_a)).norm(), 1e-7);  // p_a += v_a dt (ECEF rounding of 20 steps)
  EXPECT_LT((f.antenna_v_e() - v_a).norm(), 1e-12);
  // Var(p) = σ_p² + σ_v² T² + q T³/3, Var(v) = σ_v² + q T (horizontal q = 1, vertical 0.25 m²/s³).
  const Geodetic llh = geodetic_from_ecef(p_e);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  const Eigen::Matrix3d Pp = Ren.transpose() * f.P().block<3, 3>(a, a) * Ren;
  const Eigen::Matrix3d Pv = Ren.transpose() * f.P().block<3, 3>(a + 3, a + 3) * Ren;
  EXPECT_NEAR(Pp(0, 0), 1e-4 + 1e-6 + 1.0 / 3.0, 1e-9);
  EXPECT_NEAR(Pp(2, 2), 1e-4 + 1e-6 + 0.25 / 3.0, 1e-9);
  EXPECT_NEAR(Pv(1, 1), 1e-6 + 1.0, 1e-9);
  EXPECT_NEAR(Pv(2, 2), 1e-6 + 0.25, 1e-9);
  EXPECT_NEAR(f.P()(a, ins::kPos.offset), 0.0, 1e-12);  // independent of the foot until a tie
  EXPECT_NEAR(f.P()(a + 6, a + 6), 0.01, 1e-12);         // the arm's error: a random constant
}

TEST(AntennaState, TieGateInflatesTheNoiseOfAnAntennaFarFromTheFoot) {
  const EngineOptions o = antenna_options();
  const Eigen::Vector3d p_e = ecef_from_geodetic(Geodetic{0.9, -0.2, 30.0});
  for (const double offset_m : {0.05, 3.0}) {
    ErrorStateFilter f(o, 1);
    f.init(level_nav(p_e), ins::ImuErrors{}, 0.1);
    f.set_block_sigma(ins::kPos, 0.01);
    const LeverArm arm = filter_lever_arm(f, o);
    const Eigen::Matrix3d Ren = R_e_n(0.9, -0.2);
    // The antenna held by the phase to 1 cm, offset_m north of foot + arm.
    f.init_antenna(p_e + arm.arm_e + Ren * Eigen::Vector3d(offset_m, 0, 0), Eigen::Vector3d::Zero(),
                   Eigen::Matrix3d::Identity() * 1e-4, Eigen::Matrix3d::Identity() * 1e-4,
                   Eigen::Matrix3d::Identity() * 1e-4);
    EngineSummary sum;
    StrideVelocity stride;
    const Eigen::Vector3d before = f.antenna_p_e();
    antenna_tie_update(f, o, stride, /*mid_stance=*/true, sum);
    if (offset_m < 1.0) {
      EXPECT_EQ(sum.carrier.antenna_ties, 2);  // position and velocity halves inside the gate
      EXPECT_EQ(sum.carrier.antenna_ties_inflated, 0);
    } else {
      // 3 m against σ = √(0.01² + 0.01² + 0.01² + 0.1²) per axis: d² ≈ 870 > χ²(3, 0.999) = 16.3.
      EXPECT_EQ(sum.carrier.antenna_ties, 1);  // the velocity half
      EXPECT_EQ(sum.carrier.antenna_ties_inflated, 1);
      // The position half's noise ×d²/χ² ≈ 53: the antenna moves ≈ 0.5 mm (at the nominal σ it would move 3 cm).
      EXPECT_LT((f.antenna_p_e() - before).norm(), 1e-3);
    }
  }
}

}  // namespace
}  // namespace pednav::fusion
