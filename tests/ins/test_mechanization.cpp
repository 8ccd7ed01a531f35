// SPDX-License-Identifier: BSD-2-Clause
// ECEF mechanization: gravity model, stationary drift (1 h), Schuler period, foot-like motion per rate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include "core/geodesy.hpp"
#include "ins/gravity.hpp"
#include "ins/mechanization.hpp"
#include "motion.hpp"

namespace pednav::ins {
namespace {

using test::FootMotion;
using test::nav_state_from_ll;

constexpr double kTolGravity_mps2 = 1.5e-4;  // vs Somigliana at h = 0; J2-only truncation reaches 1.2e-4 at the pole

// Somigliana normal gravity (WGS84) at latitude [rad], h = 0: independent check of the J2 model.
double somigliana(double lat) {
  const double ge = 9.7803253359, k = 0.00193185265241, e2 = wgs84::kE2;
  const double s2 = std::sin(lat) * std::sin(lat);
  return ge * (1 + k * s2) / std::sqrt(1 - e2 * s2);
}

TEST(Gravity, MatchesSomiglianaAndPointsAlongEllipsoidNormal) {
  for (double lat_deg : {0.0, 30.0, 45.0, 60.0, 89.9}) {
    const double lat = lat_deg * kDegToRad;
    const Eigen::Vector3d p = ecef_from_geodetic({lat, 0.3, 0.0});
    const Eigen::Vector3d g = gravity_ecef(p);
    EXPECT_NEAR(g.norm(), somigliana(lat), kTolGravity_mps2) << lat_deg;
    // Deflection from the ellipsoid normal (down) stays below 1e-5 rad with the J2 model.
    const Eigen::Vector3d down = R_e_n(lat, 0.3).col(2);
    EXPECT_LT(g.normalized().cross(down).norm(), 1e-5) << lat_deg;
  }
  // Free-air gradient about -3.086e-6 (m/s^2)/m.
  const Eigen::Vector3d p0 = ecef_from_geodetic({0.8, 0.1, 0.0}), p1 = ecef_from_geodetic({0.8, 0.1, 1000.0});
  EXPECT_NEAR((gravity_ecef(p1).norm() - gravity_ecef(p0).norm()) / 1000.0, -3.086e-6, 0.01e-6);
}

std::vector<ImuSample> stationary_samples(const NavState& s, double rate_hz, double duration_s) {
  test::Kinematics k{s.p_eb_e, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), s.R_e_b(), Eigen::Vector3d::Zero()};
  const ImuSample one = test::imu_from_kinematics(GpsTime(), k);
  std::vector<ImuSample> out;
  const int64_t step = std::llround(1e9 / rate_hz);
  for (int64_t i = 0; i * step <= std::llround(duration_s * 1e9); ++i) {
    ImuSample x = one;
    x.t = s.t.plus_ns(i * step);
    out.push_back(x);
  }
  return out;
}

NavState run(NavState s, const std::vector<ImuSample>& samples, double rate_hz,
             const std::function<void(const NavState&)>& each = {}) {
  IncrementIntegrator integ({rate_hz, true, true});
  for (const auto& x : samples) {
    integ.push(x, [&](const ImuIncrement& inc) {
      s = mechanize(s, inc);
      if (each) each(s);
    });
  }
  return s;
}

TEST(Mechanization, StationaryOneHourDriftsLessThanOneCentimetre) {
  constexpr double kTolHorizontal_m = 0.01;  // issue 12 "Done when"
  // Measured (2026-12-05, Release): max horizontal drift 9.39e-5 m, final vertical -9.55e-4 m (exact data: the drift
  // is the mechanization's own discretization). Bounds +30 % (another libm/compiler; docs/conventions.md
  // "Test bounds").
  constexpr double kMeasuredBoundHorizontal_m = 1.2e-4;
  constexpr double kMeasuredBoundVertical_m = 1.25e-3;
  const GpsTime t0 = GpsTime::from_week_tow(2000, 100.0);
  const NavState s0 =
      nav_state_from_ll(t0, 45.0, 7.0, 250.0, 0.1, -0.2, 1.0);  // tilted, heading 57 deg
  const auto samples = stationary_samples(s0, 100.0, 3600.0);
  double max_h = 0.0;
  const NavState s1 = run(s0, samples, 20.0, [&](const NavState& s) {
    const Eigen::Vector3d d = ned_from_ecef(s.p_eb_e, s0.p_eb_e);
    max_h = std::max(max_h, d.head<2>().norm());
  });
  const Eigen::Vector3d d = ned_from_ecef(s1.p_eb_e, s0.p_eb_e);
  std::printf("[stationary 1 h @20 Hz] max horizontal drift %.3e m, final vertical %.3e m\n", max_h, d.z());
  EXPECT_LT(max_h, kTolHorizontal_m);
  EXPECT_LT(max_h, kMeasuredBoundHorizontal_m);
  EXPECT_LT(std::abs(d.z()), kMeasuredBoundVertical_m);
  EXPECT_NEAR((s1.t - s0.t), 3600.0, 1e-9);
}

TEST(Mechanization, SchulerPeriodFromInitialVelocityError) {
  // Equator, initial north velocity error 0.1 m/s, exact stationary IMU data: the north position error is
  // (v0/ω_s) sin(ω_s t); its zero crossings give the period. Theory 2π sqrt(r/γ) ≈ 84.4 min (issue 12).
  constexpr double kSchuler_s = 84.4 * 60.0;
  constexpr double kTolRel = 0.01;
  const NavState truth = nav_state_from_ll(GpsTime(), 0.0, 20.0, 0.0, 0.0, 0.0, 0.0);
  NavState s = truth;
  const Eigen::Matrix3d Ren = R_e_n(0.0, 20.0 * kDegToRad);
  s.v_eb_e = Ren * Eigen::Vector3d(0.1, 0.0, 0.0);
  const auto samples = stationary_samples(truth, 20.0, 1.15 * kSchuler_s);
  std::vector<double> crossings;
  double prev_n = 0.0, prev_t = 0.0, max_n = 0.0;
  run(s, samples, 10.0, [&](const NavState& x) {
    const double n = ned_from_ecef(x.p_eb_e, truth.p_eb_e).x();
    const double t = x.t - truth.t;
    max_n = std::max(max_n, n);
    if (prev_t > 60.0 && ((prev_n > 0) != (n > 0))) crossings.push_back(prev_t + (t - prev_t) * prev_n / (prev_n - n));
    prev_n = n;
    prev_t = t;
  });
  ASSERT_GE(crossings.size(), 2u);
  const double period = crossings[1];
  std::printf("[schuler] half-period crossing %.1f s, full %.1f s = %.2f min (amplitude %.1f m)\n", crossings[0],
              period, period / 60.0, max_n);
  EXPECT_NEAR(period, kSchuler_s, kTolRel * kSchuler_s);
  EXPECT_NEAR(2.0 * crossings[0], kSchuler_s, kTolRel * kSchuler_s);
  // Amplitude v0/ω_s = v0 T/(2π) with the measured period (measured 2026-12-05: 80.5 m, the theory's value).
  EXPECT_NEAR(max_n, 0.1 * period / (2.0 * kPi), kTolRel * max_n);
}

struct RateResult {
  double rate_hz, max_vs_full_m, end_vs_full_m, end_vs_truth_m, max_att_vs_full_rad;
};

TEST(Mechanization, FootMotionAtReducedRatesStaysNearFullRate) {
  // 400 Hz exact IMU of the analytic gait (pitch rate peaks 7 rad/s), 60 s, mechanized at 10/20/50/100 Hz vs
  // 400 Hz (full rate). Issue 12: 20 Hz within a few centimetres of full rate (kTol20Hz_m, the target).
  // Measured (2026-12-05, Release): max |dp| vs full 4.55e-6 / 4.50e-6 / 4.52e-6 / 5.19e-6 m at 10 / 20 / 50 /
  // 100 Hz (the end-point difference is the max), attitude vs full <= 2.9e-13 rad; bound 6.5e-6 m = the largest
  // +25 % (another libm/compiler). The attitude agrees to round-off at every rate (the increments compose exactly),
  // so its bound is a round-off bound, 1e-11 rad: a modelling difference would show at 1e-9 rad or more.
  // End error against the truth 0.2663 m at every rate, full rate included: it is not the mechanization rate but the
  // samples-to-increments step (point samples of a 7 rad/s rate integrated with an O(Δt²) error per sample: 1.07 /
  // 0.266 / 0.067 / 0.017 m with 200 / 400 / 800 / 1600 Hz samples, measured 2026-12-05; attitude error 7.2e-5 rad
  // at 400 Hz tilts gravity into the horizontal). Bound 0.30 m (+13 %, another libm/compiler).
  constexpr double kImuRate_hz = 400.0, kDuration_s = 60.0;
  constexpr double kTol20Hz_m = 0.03;
  constexpr double kMeasuredBoundVsFull_m = 6.5e-6;
  constexpr double kRoundOffAtt_rad = 1e-11;
  constexpr double kMeasuredBoundVsTruth_m = 0.30;
  const FootMotion motion;
  const auto samples = motion.samples(kImuRate_hz, kDuration_s);
  double peak_rate = 0.0;
  for (const auto& x : samples) peak_rate = std::max(peak_rate, x.omega_ib_b.norm());
  EXPECT_NEAR(peak_rate, 7.0, 0.3);
  const NavState s0 = test::nav_from_kinematics(samples.front().t, motion.at(0.0));
  // Full-rate solution at every 0.1 s (a grid point of every rate).
  auto trace = [&](double rate) {
    std::vector<NavState> out;
    run(s0, samples, rate, [&](const NavState& s) {
      if (s.t.ns() % 100'000'000 == 0) out.push_back(s);
    });
    return out;
  };
  const auto full = trace(kImuRate_hz);
  const NavState truth_end = test::nav_from_kinematics(full.back().t, motion.at(full.back().t.seconds()));
  const double full_vs_truth_m = (full.back().p_eb_e - truth_end.p_eb_e).norm();
  std::printf("[foot 60 s] full-rate (400 Hz) end error vs truth %.4f m\n", full_vs_truth_m);
  EXPECT_LT(full_vs_truth_m, kMeasuredBoundVsTruth_m);
  std::vector<RateResult> results;
  for (double rate : {10.0, 20.0, 50.0, 100.0}) {
    const auto tr = trace(rate);
    ASSERT_EQ(tr.size(), full.size());
    RateResult r{rate, 0, 0, 0, 0};
    for (size_t i = 0; i < tr.size(); ++i) {
      r.max_vs_full_m = std::max(r.max_vs_full_m, (tr[i].p_eb_e - full[i].p_eb_e).norm());
      r.max_att_vs_full_rad = std::max(r.max_att_vs_full_rad, tr[i].q_e_b.angularDistance(full[i].q_e_b));
    }
    r.end_vs_full_m = (tr.back().p_eb_e - full.back().p_eb_e).norm();
    r.end_vs_truth_m = (tr.back().p_eb_e - truth_end.p_eb_e).norm();
    results.push_back(r);
    std::printf("[foot 60 s] %5.0f Hz: max |dp| vs full %.2e m, end %.2e m, end vs truth %.4f m, max att %.2e rad\n",
                rate, r.max_vs_full_m, r.end_vs_full_m, r.end_vs_truth_m, r.max_att_vs_full_rad);
  }
  for (const auto& r : results) {
    EXPECT_LT(r.max_vs_full_m, kTol20Hz_m) << r.rate_hz << " Hz";
    EXPECT_LT(r.max_vs_full_m, kMeasuredBoundVsFull_m) << r.rate_hz << " Hz";
    EXPECT_LE(r.end_vs_full_m, r.max_vs_full_m) << r.rate_hz << " Hz";  // the end is one of the compared epochs
    EXPECT_LT(r.end_vs_truth_m, kMeasuredBoundVsTruth_m) << r.rate_hz << " Hz";
    EXPECT_LT(r.max_att_vs_full_rad, kRoundOffAtt_rad) << r.rate_hz << " Hz";
  }
}

}  // namespace
}  // namespace pednav::ins

namespace pednav::ins {
namespace {

// The g-sensitive gyro error (docs/error_state.md §5): ω_measured = (1 + s_g) ω + b_g + G_g f with f the true
// specific force. correct_sample removes it with the corrected specific force; correct_increment with the corrected
// plain velocity increment (∫ G_g f dt = G_g υ).
TEST(Mechanization, CorrectionRemovesTheGSensitiveRate) {
  ImuErrors e;
  e.b_g = Eigen::Vector3d(0.01, -0.02, 0.005);
  e.b_a = Eigen::Vector3d(0.05, 0.1, -0.08);
  e.G_g << 2e-3, -1e-3, 3e-3, 1e-3, 2.5e-3, -2e-3, -3e-3, 1.5e-3, 1e-3;
  const Eigen::Vector3d omega(1.5, -4.0, 0.3), f(12.0, -3.0, -25.0);
  ImuSample s;
  s.omega_ib_b = omega + e.b_g + e.G_g * f;
  s.f_ib_b = f + e.b_a;
  const ImuSample c = correct_sample(s, e);
  EXPECT_LT((c.f_ib_b - f).norm(), 1e-12);
  EXPECT_LT((c.omega_ib_b - omega).norm(), 1e-12);
  ImuIncrement inc;
  inc.dt_s = 0.05;
  inc.alpha_b = inc.dtheta_b = s.omega_ib_b * inc.dt_s;
  inc.upsilon_b = inc.dv_b = s.f_ib_b * inc.dt_s;
  inc.omega_end_b = s.omega_ib_b;
  inc.f_end_b = s.f_ib_b;
  const ImuIncrement ci = correct_increment(inc, e);
  EXPECT_LT((ci.alpha_b - omega * inc.dt_s).norm(), 1e-12);
  EXPECT_LT((ci.dtheta_b - omega * inc.dt_s).norm(), 1e-12);
  EXPECT_LT((ci.omega_end_b - omega).norm(), 1e-12);
  // Without the G term the rate would be off by |G f| ≈ 0.1 rad/s here: the check above is not vacuous.
  EXPECT_GT((e.G_g * f).norm(), 0.05);
}

}  // namespace
}  // namespace pednav::ins
