// SPDX-License-Identifier: BSD-2-Clause
// Seed 001 consistency test (issue 5, ../shared/DESIGN.md "Measurement models"): ZUPT-only on a simulated walk.
// With form D (seed 001 eq. 8) heading is unobservable and its variance grows as a random walk,
// P_yaw(k+1) = P_yaw(k) + σ_ω² T per step (seed 001 eq. 19), i.e. at σ_ω² [rad²/s]; with form F (eq. 9) the
// attitude error leaks into the ZUPT through v̂ × β and the yaw variance is falsely bounded (eq. 24).
// The test fails if the two forms are swapped. docs/fusion.md §5.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/engine.hpp"
#include "io/scenario_config.hpp"
#include "sim/simulator.hpp"

namespace pednav {
namespace {

// A 4-minute walk around a 40 m x 25 m block (level ground), IMU only.
const char* kWalkYaml = R"(
name: zupt_consistency_walk
seed: 17
start: {gps_week: 2300, gps_tow_s: 400000}
origin: {lat_deg: 51.08, lon_deg: -114.13, h_m: 1050}
route:
  static_start_s: 10
  static_end_s: 5
  waypoints:
    - {e_m: 0, n_m: 0}
    - {e_m: 40, n_m: 0}
    - {e_m: 40, n_m: 25}
    - {e_m: 0, n_m: 25}
    - {e_m: 0, n_m: 0}
    - {e_m: 40, n_m: 0}
    - {e_m: 40, n_m: 25}
    - {e_m: 0, n_m: 25}
    - {e_m: 0, n_m: 0}
gait: {speed_mps: 1.1, cycle_s: 1.2, stance_fraction: 0.3}
imu: {rate_hz: 100, spec: crista, errors: true, misalignment_mrad: 0}
gnss: {enabled: false}
)";

// Crista-class white noise only, so seed 001 eq. 19 applies (sensor errors r, ε white with PSDs σ_f², σ_ω²).
// The bias states need a positive (but negligible) variance: 1e-6 rad/s over 250 s adds 6e-8 rad² to P_yaw,
// < 1e-4 of the σ_ω² T growth.
constexpr double kStandardGravity = 9.80665;  // [m/s^2] (ug units)

ins::ImuSpec white_noise_spec() {
  ins::ImuSpec s;
  s.name = "white_noise";
  s.gyro_arw = 0.1 * kDegToRad;           // 0.1 deg/s/sqrt(Hz) [rad/sqrt(s)]
  s.accel_vrw = 200e-6 * kStandardGravity;  // 200 ug/sqrt(Hz) [m/s/sqrt(s)]
  s.gyro_bias_instability = 1e-6;         // [rad/s]
  s.gyro_bias_tau_s = 3600.0;
  s.accel_bias_instability = 1e-5;        // [m/s^2]
  s.accel_bias_tau_s = 3600.0;
  return s;
}

// Issue 5 asks for ±25 %; in the linear model eq. 19 is exact for form D (yaw is driven by gyro noise only), so
// the covariance (deterministic) is held to ±5 %: ±25 % would also accept form F's 0.83 on this 4-min walk,
// i.e. would not fail when the forms are swapped. Measured 2026-12-05 (Release): D with the linearization reset of
// docs/fusion.md §5.1 0.99869 (|ratio − 1| 1.310e-3), form F 0.832 (falling further on longer walks: seed 001 eq. 24). Beside the
// ±5 % of eq. 19, form D's measured deviation from 1 is bounded at +50 % (a covariance, deterministic), and form F's
// ratio at 0.832 ± 5 % of it.
constexpr double kRandomWalkTolerance = 0.05;  // form D: growth rate within ±5 % of σ_ω²
constexpr double kFormDDevMax = 1.310e-3 * 1.5;  // form D: measured |ratio − 1| + 50 %
constexpr double kBoundedRatio = 0.9;          // form F: growth rate below 0.9 σ_ω² (heading falsely observed)
constexpr double kFormFRatio = 0.832;           // form F: measured growth rate / σ_ω²
constexpr double kInitialYawSigmaRad = 1.0 * kDegToRad;

struct YawGrowth {
  double p_start_rad2 = 0, p_end_rad2 = 0, duration_s = 0;
  double rate_rad2_per_s() const { return (p_end_rad2 - p_start_rad2) / duration_s; }
  double max_p_rad2 = 0;
};

class ZuptConsistency : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto file = io::parse_scenario(kWalkYaml, "zupt_consistency.yaml", ".");
    ASSERT_TRUE(file.has_value()) << file.error().message;
    sim::Scenario sc = file->scenario;
    sc.imu.spec = white_noise_spec();
    auto s = sim::simulate(sc);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    sim_ = new sim::Simulation(std::move(*s));
  }
  static void TearDownTestSuite() {
    delete sim_;
    sim_ = nullptr;
  }

  static YawGrowth run(fusion::ZuptForm form) {
    fusion::EngineOptions o;
    o.mode = fusion::Mode::kInsOnly;
    o.spec = white_noise_spec();
    o.zupt_form = form;
    const ins::NavState& t0 = sim_->truth.nav.front();
    o.initial_position_e = t0.p_eb_e;
    const Geodetic llh = geodetic_from_ecef(t0.p_eb_e);
    const Eigen::Vector3d rpy = euler_from_R_n_b(R_e_n(llh.lat, llh.lon).transpose() * t0.R_e_b());
    o.initial_yaw_rad = rpy.z();
    o.initial_sigma_yaw_rad = kInitialYawSigmaRad;
    // The whole yaw variance inside P: this test is about the filter's own covariance recursion (seed 001), which
    // the heading-frame split of docs/fusion.md §5.5 would hide.
    o.ins_heading_as_frame = false;
    fusion::EngineInputs in;
    in.imu = &sim_->imu;
    auto r = fusion::run_forward(in, o);
    EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
    YawGrowth g;
    if (!r || r->epochs.size() < 2) return g;
    EXPECT_TRUE(r->summary.covariance_healthy);
    EXPECT_GT(r->summary.zupt_updates, 1000);
    const auto& e = r->epochs;
    g.p_start_rad2 = e.front().sd_yaw_rad * e.front().sd_yaw_rad;
    g.p_end_rad2 = e.back().sd_yaw_rad * e.back().sd_yaw_rad;
    g.duration_s = e.back().t - e.front().t;
    for (const auto& x : e) g.max_p_rad2 = std::max(g.max_p_rad2, x.sd_yaw_rad * x.sd_yaw_rad);
    return g;
  }

  static sim::Simulation* sim_;
};
sim::Simulation* ZuptConsistency::sim_ = nullptr;

TEST_F(ZuptConsistency, FormDYawVarianceGrowsAsARandomWalk) {
  const double q = white_noise_spec().gyro_arw * white_noise_spec().gyro_arw;  // σ_ω² [rad²/s]
  const YawGrowth g = run(fusion::ZuptForm::kDynamic);
  const double ratio = g.rate_rad2_per_s() / q;
  std::printf("[ form D ] yaw variance %.4g -> %.4g rad^2 over %.0f s: growth %.4g rad^2/s = %.3f x sigma_w^2 "
              "(sigma_w^2 T per 1.2 s step: %.4g rad^2)\n",
              g.p_start_rad2, g.p_end_rad2, g.duration_s, g.rate_rad2_per_s(), ratio, q * 1.2);
  std::printf("[ form D ] |ratio - 1| %.3e\n", std::abs(ratio - 1.0));
  EXPECT_NEAR(ratio, 1.0, kRandomWalkTolerance) << "seed 001 eq. 19: P_yaw grows by sigma_w^2 T per step";
  EXPECT_NEAR(ratio, 1.0, kFormDDevMax) << "measured deviation from eq. 19";
  // A random walk never shrinks: the yaw variance at the end is the largest.
  EXPECT_NEAR(g.max_p_rad2, g.p_end_rad2, 1e-3 * g.p_end_rad2);
}

TEST_F(ZuptConsistency, FormFYawVarianceIsFalselyBounded) {
  const double q = white_noise_spec().gyro_arw * white_noise_spec().gyro_arw;
  const YawGrowth g = run(fusion::ZuptForm::kFull);
  const double ratio = g.rate_rad2_per_s() / q;
  std::printf("[ form F ] yaw variance %.4g -> %.4g rad^2 (max %.4g) over %.0f s: growth %.4g rad^2/s = %.3f x "
              "sigma_w^2\n",
              g.p_start_rad2, g.p_end_rad2, g.max_p_rad2, g.duration_s, g.rate_rad2_per_s(), ratio);
  EXPECT_LT(ratio, kBoundedRatio) << "seed 001 eq. 24: with form F the heading looks observable";
  EXPECT_NEAR(ratio, kFormFRatio, 0.05 * kFormFRatio);
}

// docs/fusion.md §5.5: in ins mode the initial heading σ is carried outside the filter as a rotation about the start.
// In the linear model form D cannot observe that rotation, so the split must not change the reported σ: the frame
// term added to the output replaces the yaw variance removed from P. The trajectories differ only through
// second-order effects (stance edges where the detected ZUPT is not exact). Measured 2026-12-05 (Release): max
// difference 0.856 m, horizontal RMS error vs truth 1.024 m (split) vs 0.804 m (whole), end error 0.987 vs 0.983 m,
// largest horizontal σ 10.93 m, final σ_yaw 10.12° / 10.08°. Errors bounded at the measured figure + 30 % (a 4-min
// filter run), σ within ±10 % (a covariance: deterministic). The max difference, the figure that says "equivalent",
// at + 5 % (another libm): 0.8562 m in the Release and in the ASan + UBSan RelWithDebInfo build alike (2026-12-06;
// it was + 30 %, 1.11 m).
constexpr double kFrameYawSigmaRad = 10.0 * kDegToRad;  // the run configurations' default initial σ_yaw
constexpr double kSplitTrajectoryTol_m = 0.8562 * 1.05;  // max horizontal difference of the two runs
constexpr double kSplitSigmaTolRel = 0.05;              // reported horizontal / yaw σ agree within 5 %
constexpr double kRmsSplitMax_m = 1.024 * 1.3, kRmsWholeMax_m = 0.804 * 1.3;
constexpr double kEndSplitMax_m = 0.987 * 1.3, kEndWholeMax_m = 0.983 * 1.3;
constexpr double kMaxSdH_m = 10.93, kEndSdYawSplit_deg = 10.12, kSigmaTol = 0.10;

TEST_F(ZuptConsistency, HeadingFrameSplitIsEquivalentWhenZuptsAreExact) {
  auto run_split = [&](bool as_frame) {
    fusion::EngineOptions o;
    o.mode = fusion::Mode::kInsOnly;
    o.spec = white_noise_spec();
    const ins::NavState& t0 = sim_->truth.nav.front();
    o.initial_position_e = t0.p_eb_e;
    const Geodetic llh = geodetic_from_ecef(t0.p_eb_e);
    o.initial_yaw_rad = euler_from_R_n_b(R_e_n(llh.lat, llh.lon).transpose() * t0.R_e_b()).z();
    o.initial_sigma_yaw_rad = kFrameYawSigmaRad;
    o.ins_heading_as_frame = as_frame;
    fusion::EngineInputs in;
    in.imu = &sim_->imu;
    auto r = fusion::run_forward(in, o);
    EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
    return r ? std::move(*r) : fusion::EngineResult{};
  };
  const auto split = run_split(true), whole = run_split(false);
  // Horizontal error against the truth (nearest truth sample; both at the IMU rate grid).
  auto truth_error_m = [&](const fusion::EpochOutput& e) {
    const auto& tn = sim_->truth.nav;
    const auto it = std::lower_bound(tn.begin(), tn.end(), e.t, [](const ins::NavState& s, GpsTime t) { return s.t < t; });
    const ins::NavState& x = (it == tn.end()) ? tn.back() : *it;
    const Geodetic g = geodetic_from_ecef(x.p_eb_e);
    return (R_e_n(g.lat, g.lon).transpose() * (e.nav.p_eb_e - x.p_eb_e)).head<2>().norm();
  };
  double rms_split = 0, rms_whole = 0;
  for (size_t k = 0; k < split.epochs.size() && k < whole.epochs.size(); ++k) {
    rms_split += std::pow(truth_error_m(split.epochs[k]), 2);
    rms_whole += std::pow(truth_error_m(whole.epochs[k]), 2);
  }
  ASSERT_EQ(split.epochs.size(), whole.epochs.size());
  rms_split = std::sqrt(rms_split / split.epochs.size());
  rms_whole = std::sqrt(rms_whole / whole.epochs.size());
  const double end_split = truth_error_m(split.epochs.back()), end_whole = truth_error_m(whole.epochs.back());
  std::printf("[frame split] horizontal RMS error vs truth: split %.3f m, whole %.3f m; end %.3f / %.3f m\n",
              rms_split, rms_whole, end_split, end_whole);
  EXPECT_LT(rms_split, kRmsSplitMax_m);
  EXPECT_LT(rms_whole, kRmsWholeMax_m);
  EXPECT_LT(end_split, kEndSplitMax_m);
  EXPECT_LT(end_whole, kEndWholeMax_m);
  ASSERT_GT(split.epochs.size(), 100u);
  double max_diff_m = 0, max_sd_h_m = 0;
  for (size_t k = 0; k < split.epochs.size(); ++k) {
    const auto& a = split.epochs[k];
    const auto& b = whole.epochs[k];
    const Eigen::Vector3d d_n = R_e_n(geodetic_from_ecef(b.nav.p_eb_e).lat, geodetic_from_ecef(b.nav.p_eb_e).lon)
                                    .transpose() * (a.nav.p_eb_e - b.nav.p_eb_e);
    max_diff_m = std::max(max_diff_m, d_n.head<2>().norm());
    const double sd_h_a = std::sqrt(a.cov_p_n(0, 0) + a.cov_p_n(1, 1));
    const double sd_h_b = std::sqrt(b.cov_p_n(0, 0) + b.cov_p_n(1, 1));
    max_sd_h_m = std::max(max_sd_h_m, sd_h_b);
    if (sd_h_b > 1.0) {  // away from the start, where the heading term dominates
      EXPECT_NEAR(sd_h_a / sd_h_b, 1.0, kSplitSigmaTolRel) << "epoch " << k;
    }
    EXPECT_NEAR(a.sd_yaw_rad / b.sd_yaw_rad, 1.0, kSplitSigmaTolRel) << "epoch " << k;
  }
  std::printf("[frame split] max horizontal difference %.4f m, max horizontal sd %.2f m, end sd_yaw %.3f / %.3f deg\n",
              max_diff_m, max_sd_h_m, split.epochs.back().sd_yaw_rad / kDegToRad,
              whole.epochs.back().sd_yaw_rad / kDegToRad);
  EXPECT_LT(max_diff_m, kSplitTrajectoryTol_m);
  EXPECT_NEAR(max_sd_h_m, kMaxSdH_m, kSigmaTol * kMaxSdH_m);  // 10° over tens of metres: the frame term is there
  EXPECT_NEAR(split.epochs.back().sd_yaw_rad / kDegToRad, kEndSdYawSplit_deg, kSigmaTol * kEndSdYawSplit_deg);
}

}  // namespace
}  // namespace pednav
