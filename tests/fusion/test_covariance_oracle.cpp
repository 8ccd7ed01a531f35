// SPDX-License-Identifier: BSD-2-Clause
// Closed-form covariance oracles of seed 001 (issue 9) for the filter's own covariance recursion: the engine's
// discrete error model (ins::interval_error_model at the 20 Hz mechanization rate) and its ZUPT Jacobian
// (fusion::zupt_jacobian, Joseph update) in the seed 001 setting — constant step period T, one instantaneous ZUPT
// per step, white sensor noises (PSDs σ_f², σ_ω²), IMU at rest so that the computed velocity at the ZUPT is zero.
// Checked: stationary tilt and velocity covariances before/after the ZUPT (seed 001 eqs. 16-17) and the yaw random
// walk P_ψ(k+1) = P_ψ(k) + σ_ω² T (eq. 19).
//
// Seed 001's eqs. 16-17 are the fixed point of the recursion with the noise of a step added once, at its end
// (P⁻ = F P Fᵀ + diag(σ_f² T, σ_ω² T)), with κ = σ_f / (σ_ω g T) (eq. 18 as printed has σ² in the numerator; only
// κ = σ_f/(σ_ω g T) makes eq. 16 the fixed point of eq. 13, docs/consistency.md §2). The filter integrates the
// continuous noise over the step, whose fixed point is P_β = √(σ_ω² σ_f² / g² + σ_ω⁴ T² / 12) (docs/consistency.md
// eq. C.3). The two agree when κ ≫ 1; for κ ~ 0.1 (MEMS gyros, T ~ 1 s) eq. 16 is ~3× the continuous value. So:
// the paper's formulas are checked at κ = 20 (within 5 %), the continuous-noise ones at a MEMS setting (within 2 %).
// The form D / form F yaw test on the engine (eq. 19 vs eq. 24) is tests/fusion/test_zupt_consistency.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/geodesy.hpp"
#include "fusion/engine.hpp"
#include "fusion/stance_updates.hpp"
#include "ins/alignment.hpp"
#include "ins/error_state.hpp"
#include "ins/gravity.hpp"
#include "ins/mechanization.hpp"

namespace pednav {
namespace {

constexpr double kMechRateHz = 20.0;       // engine default mechanization rate [Hz]
constexpr double kZuptSigmaMps = 1e-4;     // seed 001 neglects the ZUPT error Δz; a tiny one keeps S > 0 [m/s]
constexpr int kSteps = 300;                // steps to reach the stationary covariance
constexpr double kInitialAttSigmaRad = 1e-4;  // [rad]
constexpr double kPaperTol = 0.05;         // issue 9: within 5 % of eqs. 16-17, 19
constexpr double kContinuousTol = 0.02;    // continuous-noise fixed point: the recursion is exact up to Earth rate

struct Setting {
  double sigma_w;  // σ_ω gyro white noise [rad/√s]
  double sigma_f;  // σ_f accelerometer white noise [m/s/√s]
  double T;        // step period [s]
};

// Stationary covariances of one horizontal channel (δv_i, β_j) and the yaw growth per step, from the recursion.
struct Result {
  double P_beta_post[2], P_beta_prior[2], P_dv_prior[2], P_dvbeta_prior[2];  // per horizontal channel (N, E)
  double yaw_growth_per_step = 0.0;  // [rad²] mean over the last 100 steps
  double g = 0.0;                    // local gravity magnitude [m/s²]
};

ins::ImuSpec white(const Setting& s) {
  ins::ImuSpec spec;
  spec.name = "white_noise";
  spec.gyro_arw = s.sigma_w;
  spec.accel_vrw = s.sigma_f;
  return spec;  // no bias or scale-factor noise: seed 001's r, ε are white
}

Result run_recursion(const Setting& s, fusion::ZuptForm form) {
  const ins::ImuSpec spec = white(s);
  ins::ErrorStateLayout layout;
  const Geodetic llh{51.08 * kDegToRad, -114.13 * kDegToRad, 1050.0};
  const Eigen::Vector3d p_e = ecef_from_geodetic(llh);
  ins::NavState x = ins::nav_state_at_rest(GpsTime::from_week_tow(2300, 0.0), p_e, 0.0, 0.0, 0.3);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  // Exact increments of an IMU at rest: ω_ib = ω_ie, f_ib = −g (gravity incl. centrifugal), both constant in b.
  const Eigen::Vector3d w_b = x.R_e_b().transpose() * Eigen::Vector3d(0, 0, wgs84::kOmegaIE_radps);
  const Eigen::Vector3d f_b = -(x.R_e_b().transpose() * ins::gravity_ecef(p_e));
  const double dt = 1.0 / kMechRateHz;
  const int sub = static_cast<int>(std::lround(s.T * kMechRateHz));
  // Small initial attitude σ: with a large initial yaw variance the Earth rate makes yaw slowly observable through
  // the tilts (gyrocompassing), which would mask eq. 19's σ_ω² T growth at the κ = 20 setting's tiny σ_ω.
  Eigen::MatrixXd P = ins::initial_covariance(layout, spec, 1.0, 0.1, Eigen::Vector3d::Constant(kInitialAttSigmaRad));
  Result r;
  r.g = f_b.norm();
  std::vector<double> yaw;
  for (int k = 0; k < kSteps; ++k) {
    for (int i = 0; i < sub; ++i) {
      ins::ImuIncrement inc;
      inc.t0 = x.t;
      inc.t1 = x.t.plus_s(dt);
      inc.dt_s = dt;
      inc.alpha_b = inc.dtheta_b = w_b * dt;
      inc.upsilon_b = inc.dv_b = f_b * dt;
      inc.dp_b = 0.5 * f_b * dt * dt;
      inc.omega_end_b = w_b;
      inc.f_end_b = f_b;
      inc.samples = 1;
      ins::NavState after = ins::mechanize(x, inc);
      const ins::DiscreteErrorModel m = ins::interval_error_model(layout, spec, x, after, inc);
      P = m.Phi * P * m.Phi.transpose() + m.Qd;
      x = after;
      x.v_eb_e.setZero();  // the IMU is at rest: keep the nominal on the truth (the recursion is about P)
      x.p_eb_e = p_e;
    }
    const Eigen::MatrixXd P_prior = P;
    // Instantaneous ZUPT (seed 001 eq. 8 / 9) with the engine's Jacobian; Joseph form.
    const int n = layout.dim();
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3, n);
    const Eigen::Matrix<double, 3, 6> J = fusion::zupt_jacobian(x.v_eb_e, form);
    H.block<3, 3>(0, ins::kVel.offset) = J.leftCols<3>();
    H.block<3, 3>(0, ins::kAtt.offset) = J.rightCols<3>();
    const Eigen::Matrix3d R = Eigen::Matrix3d::Identity() * kZuptSigmaMps * kZuptSigmaMps;
    const Eigen::MatrixXd S = H * P * H.transpose() + R;
    const Eigen::MatrixXd K = P * H.transpose() * S.inverse();
    const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(n, n) - K * H;
    P = IKH * P * IKH.transpose() + K * R * K.transpose();
    // Resolve the velocity and attitude blocks in NED.
    auto ned = [&](const Eigen::MatrixXd& M, int a, int b) {
      return Eigen::Matrix3d(Ren.transpose() * M.block<3, 3>(a, b) * Ren);
    };
    const Eigen::Matrix3d Paa = ned(P, ins::kAtt.offset, ins::kAtt.offset);
    const Eigen::Matrix3d Paa_prior = ned(P_prior, ins::kAtt.offset, ins::kAtt.offset);
    const Eigen::Matrix3d Pvv_prior = ned(P_prior, ins::kVel.offset, ins::kVel.offset);
    const Eigen::Matrix3d Pva_prior = ned(P_prior, ins::kVel.offset, ins::kAtt.offset);
    yaw.push_back(Paa(2, 2));
    // Channel N: (δv_N, tilt about E); channel E: (δv_E, tilt about N) (seed 001 eqs. 14-15).
    r.P_beta_post[0] = Paa(1, 1);
    r.P_beta_post[1] = Paa(0, 0);
    r.P_beta_prior[0] = Paa_prior(1, 1);
    r.P_beta_prior[1] = Paa_prior(0, 0);
    r.P_dv_prior[0] = Pvv_prior(0, 0);
    r.P_dv_prior[1] = Pvv_prior(1, 1);
    r.P_dvbeta_prior[0] = std::abs(Pva_prior(0, 1));
    r.P_dvbeta_prior[1] = std::abs(Pva_prior(1, 0));
  }
  r.yaw_growth_per_step = (yaw.back() - yaw[yaw.size() - 101]) / 100.0;
  return r;
}

// Seed 001 eqs. 16-17 (κ = σ_f / (σ_ω g T), see the file comment).
struct Closed {
  double P_beta, P_beta_prior, P_dv_prior, P_dvbeta_prior;
};
Closed paper(const Setting& s, double g) {
  const double kappa = s.sigma_f / (s.sigma_w * g * s.T);
  const double w2T = s.sigma_w * s.sigma_w * s.T, root = std::sqrt(1.0 + 4.0 * kappa * kappa);
  return {0.5 * w2T * (root + 1.0), 0.5 * w2T * (root + 3.0),
          0.5 * w2T * g * g * s.T * s.T * (root + 1.0) + s.sigma_f * s.sigma_f * s.T,
          0.5 * w2T * g * s.T * (root + 1.0)};
}
// Fixed point with the noise integrated over the step (docs/consistency.md eqs. C.3-C.4).
Closed continuous(const Setting& s, double g) {
  const double w2 = s.sigma_w * s.sigma_w, f2 = s.sigma_f * s.sigma_f, T = s.T;
  const double p = std::sqrt(w2 * f2 / (g * g) + w2 * w2 * T * T / 12.0);
  return {p, p + w2 * T, g * g * T * T * p + f2 * T + g * g * w2 * T * T * T / 3.0, g * T * (p + 0.5 * w2 * T)};
}

// Checks each stationary covariance against the closed form within tol; returns the largest |ratio − 1|.
double expect_match(const Result& r, const Closed& c, double tol, const char* what) {
  double worst = 0.0;
  for (int i = 0; i < 2; ++i) {
    for (const double ratio : {r.P_beta_post[i] / c.P_beta, r.P_beta_prior[i] / c.P_beta_prior,
                               r.P_dv_prior[i] / c.P_dv_prior, r.P_dvbeta_prior[i] / c.P_dvbeta_prior}) {
      worst = std::max(worst, std::abs(ratio - 1.0));
    }
    std::printf("[ %s ] channel %c: P_beta %.4g vs %.4g, P_beta- %.4g vs %.4g, P_dv- %.4g vs %.4g, P_dvbeta- %.4g vs "
                "%.4g\n",
                what, i == 0 ? 'N' : 'E', r.P_beta_post[i], c.P_beta, r.P_beta_prior[i], c.P_beta_prior,
                r.P_dv_prior[i], c.P_dv_prior, r.P_dvbeta_prior[i], c.P_dvbeta_prior);
    EXPECT_NEAR(r.P_beta_post[i] / c.P_beta, 1.0, tol) << what << " eq. 16 P_beta, channel " << i;
    EXPECT_NEAR(r.P_beta_prior[i] / c.P_beta_prior, 1.0, tol) << what << " eq. 17 P_beta-, channel " << i;
    EXPECT_NEAR(r.P_dv_prior[i] / c.P_dv_prior, 1.0, tol) << what << " eq. 17 P_dv-, channel " << i;
    EXPECT_NEAR(r.P_dvbeta_prior[i] / c.P_dvbeta_prior, 1.0, tol) << what << " eq. 17 P_dvbeta-, channel " << i;
  }
  std::printf("[ %s ] largest |ratio - 1| %.3e\n", what, worst);
  return worst;
}

// Measured 2026-12-05 (Release): the largest |ratio − 1| of the eight comparisons is 2.458e-2 at κ = 20 (the model
// difference between noise added once per step and integrated over it) and 2.374e-4 for the continuous-noise fixed
// point at the MEMS setting; the yaw growth of eq. 19 is within 1.13e-4 (κ = 20) and 2.07e-4 (MEMS) of σ_ω² T. The
// recursion is deterministic: each bound is the measured deviation + 50 % (round-off and the Earth-rate terms may
// move the smallest ones by a few 1e-5), beside the tolerance (5 % / 2 %), so a change of the error model
// that stays inside the tolerance still shows.
constexpr double kPaperDevMax = 2.458e-2 * 1.5;
constexpr double kContinuousDevMax = 2.374e-4 * 1.5;
constexpr double kEq19DevMax = 2.07e-4 * 1.5;
// Eq. 16 (noise once per step) against the filter's P_β at the MEMS setting, measured 2026-12-05: 3.33×; ±5 %.
constexpr double kMemsPaperOverFilter = 3.33;

// κ = 20: accelerometer noise dominates; eqs. 16-17 and the continuous fixed point agree to ~2.5 %.
constexpr Setting kPaperRegime{1e-4, 20.0 * 1e-4 * 9.81 * 1.0, 1.0};
// MEMS (gyro 0.1 deg/√s, accelerometer 200 µg/√Hz) at seed 004's gait cycle 1.25 s: κ ≈ 0.09.
constexpr Setting kMemsRegime{0.1 * kDegToRad, 200e-6 * 9.80665, 1.25};

TEST(Seed001Oracle, StationaryCovariancesMatchEq16And17) {
  const Result r = run_recursion(kPaperRegime, fusion::ZuptForm::kDynamic);
  EXPECT_LT(expect_match(r, paper(kPaperRegime, r.g), kPaperTol, "eq. 16-17, kappa 20"), kPaperDevMax);
}

TEST(Seed001Oracle, YawIsARandomWalkEq19) {
  for (const Setting& s : {kPaperRegime, kMemsRegime}) {
    const Result r = run_recursion(s, fusion::ZuptForm::kDynamic);
    const double q = s.sigma_w * s.sigma_w * s.T;  // σ_ω² T [rad²]
    std::printf("[ eq. 19 ] yaw variance growth %.5g rad^2 per step vs sigma_w^2 T %.5g (ratio %.6f)\n",
                r.yaw_growth_per_step, q, r.yaw_growth_per_step / q);
    EXPECT_NEAR(r.yaw_growth_per_step / q, 1.0, kPaperTol);
    EXPECT_NEAR(r.yaw_growth_per_step / q, 1.0, kEq19DevMax);
  }
}

TEST(Seed001Oracle, MemsRegimeMatchesTheContinuousNoiseFixedPoint) {
  const Result r = run_recursion(kMemsRegime, fusion::ZuptForm::kDynamic);
  const Closed c = continuous(kMemsRegime, r.g);
  EXPECT_LT(expect_match(r, c, kContinuousTol, "continuous, MEMS"), kContinuousDevMax);
  // Seed 001's eq. 16 (noise added once per step) is far from the filter here: documented, not hidden.
  const Closed p = paper(kMemsRegime, r.g);
  std::printf("[ MEMS ] eq. 16 P_beta %.4g = %.2f x the filter's %.4g\n", p.P_beta, p.P_beta / r.P_beta_post[0],
              r.P_beta_post[0]);
  EXPECT_GT(p.P_beta / r.P_beta_post[0], 2.0);  // the documented gap (file comment: ~3x at kappa ~0.1)
  EXPECT_NEAR(p.P_beta / r.P_beta_post[0], kMemsPaperOverFilter, 0.05 * kMemsPaperOverFilter);
}

}  // namespace
}  // namespace pednav
