// SPDX-License-Identifier: BSD-2-Clause
// The run's fit warnings (pipeline/run_warnings, docs/fusion.md §15) on synthetic results: a walk that fits gives
// none; each misfit, provoked alone, gives its own warning with its figure.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/geodesy.hpp"
#include "pipeline/run_warnings.hpp"

namespace pednav::pipeline {
namespace {

using ::testing::HasSubstr;

struct Walk {
  double speed_mps = 1.2;     // along north
  double stride_s = 1.1;      // stance to stance
  double stance_s = 0.33;     // stance duration
  double duration_s = 60.0;
  double rate_hz = 20.0;
  double sigma_m = 0.3;       // forward horizontal σ; the smoother's is half of it
  double smoothed_offset_m = 0.0;
};

// A foot that stands still during each stance and moves between them (the stride is speed × stride_s), with its
// forward and smoothed outputs.
fusion::EngineResult walk(const Walk& w) {
  fusion::EngineResult r;
  const Eigen::Vector3d p0 = ecef_from_geodetic({51.0 * kDegToRad, -114.0 * kDegToRad, 1000.0});
  const Eigen::Matrix3d R_en = R_e_n(51.0 * kDegToRad, -114.0 * kDegToRad);
  const int n = static_cast<int>(w.duration_s * w.rate_hz);
  for (int i = 0; i < n; ++i) {
    const double t = i / w.rate_hz;
    const double k = std::floor(t / w.stride_s), phase = t - k * w.stride_s;
    const bool stance = phase < w.stance_s;
    const double north = w.speed_mps * w.stride_s * (k + (stance ? 0.0 : (phase - w.stance_s) / (w.stride_s - w.stance_s)));
    fusion::EpochOutput e;
    e.t = GpsTime::from_week_tow(2300, 1000.0 + t);
    e.nav.p_eb_e = p0 + R_en * Eigen::Vector3d(north, 0.0, 0.0);
    e.cov_p_n = Eigen::Vector3d(w.sigma_m * w.sigma_m, w.sigma_m * w.sigma_m, 0.25).asDiagonal();
    e.zupt = stance;
    r.epochs.push_back(e);
    fusion::EpochOutput s = e;
    s.cov_p_n = 0.25 * e.cov_p_n;
    // Within the σ of the difference (√(P_f − P_s) = 0.26 m per axis): 0.1 m east, alternating.
    s.nav.p_eb_e += R_en * Eigen::Vector3d(w.smoothed_offset_m, (i % 2 ? 0.1 : -0.1), 0.0);
    r.smoothed.push_back(s);
    r.summary.zupt_samples += stance ? 10 : 0;  // a 200-Hz IMU
  }
  r.summary.imu_samples_used = 10L * n;
  return r;
}

ins::ImuSpec spec() {
  ins::ImuSpec s;
  s.gyro_bias_initial = 20.0 / 3600.0 * kDegToRad;  // 20 °/h
  return s;
}

std::vector<std::string> codes(const std::vector<RunWarning>& ws) {
  std::vector<std::string> c;
  for (const auto& w : ws) c.push_back(w.code);
  return c;
}

TEST(RunWarnings, AWalkThatFitsHasNone) {
  const auto ws = run_warnings(walk({}), spec());
  EXPECT_TRUE(ws.empty()) << (ws.empty() ? "" : ws.front().message);
  EXPECT_EQ(run_warnings_json(ws).dump(), "[]");
}

TEST(RunWarnings, ForwardAndSmoothedApartBeyondTheirSigmas) {
  Walk w;
  w.smoothed_offset_m = 1.0;  // 1 m north against a difference σ of 0.26 m: every epoch beyond χ²(2) 99 %
  const auto ws = run_warnings(walk(w), spec());
  ASSERT_EQ(codes(ws), std::vector<std::string>{"forward_smoothed_disagree"});
  EXPECT_NEAR(ws[0].value, 100.0, 1e-9);
  EXPECT_EQ(ws[0].limit, 5.0);
  EXPECT_THAT(ws[0].message, HasSubstr("beyond their σ's at 100.0 % of 1200 epochs"));
  EXPECT_THAT(ws[0].hint, HasSubstr("imu.spec: auto"));
  const auto j = run_warnings_json(ws);
  EXPECT_EQ(j[0]["code"], "forward_smoothed_disagree");
}

TEST(RunWarnings, NoStancesOnAMovingTrack) {
  fusion::EngineResult r = walk({});
  for (auto& e : r.epochs) e.zupt = false;
  r.summary.zupt_samples = 0;
  const auto ws = run_warnings(r, spec());
  ASSERT_EQ(codes(ws), std::vector<std::string>{"stance_share"});
  EXPECT_EQ(ws[0].value, 0.0);
  EXPECT_THAT(ws[0].hint, HasSubstr("is the IMU on the foot?"));
}

TEST(RunWarnings, StepsTooLongForAWalk) {
  Walk w;
  w.speed_mps = 4.0;  // 4.4-m strides: 2.2-m steps
  const auto ws = run_warnings(walk(w), spec());
  ASSERT_EQ(codes(ws), std::vector<std::string>{"step_length"});
  EXPECT_NEAR(ws[0].value, 2.2, 0.05);
  EXPECT_EQ(ws[0].limit, 2.0);
}

// A 1-Hz output (GNSS epochs) catches a stance now and then: the distance between two caught ones is any number of
// strides, so the step and cadence checks do not run on it (docs/fusion.md §15.3-15.4); with the interval limit
// lifted the same output warns of 3-m steps at 0.2 strides/s (a caught stance every 4-5 s) that never happened.
TEST(RunWarnings, CoarseOutputsSkipTheStepAndCadenceChecks) {
  Walk w;
  w.rate_hz = 1.0;
  w.stride_s = 1.25;  // stances at 0, 1.25, 2.5, …: a 1-Hz epoch falls in one every 4-5 s (4-5 strides)
  w.stance_s = 0.4;
  w.duration_s = 300.0;
  const fusion::EngineResult r = walk(w);
  EXPECT_TRUE(run_warnings(r, spec()).empty());
  RunWarningLimits lifted;
  lifted.gait_output_interval_max_s = 10.0;
  lifted.max_stride_s = 10.0;
  const auto ws = run_warnings(r, spec(), lifted);
  ASSERT_EQ(codes(ws), (std::vector<std::string>{"step_length", "cadence"}));
  EXPECT_NEAR(ws[0].value, 3.0, 0.01);
  EXPECT_NEAR(ws[1].value, 0.2, 0.01);
}

TEST(RunWarnings, CadenceThatNoGaitHas) {
  Walk w;
  w.stride_s = 0.4;   // 2.5 strides/s
  w.stance_s = 0.15;
  w.speed_mps = 2.0;  // 0.8-m strides: a plausible step, an implausible cadence
  const auto ws = run_warnings(walk(w), spec());
  ASSERT_EQ(codes(ws), std::vector<std::string>{"cadence"});
  EXPECT_NEAR(ws[0].value, 2.5, 0.2);
  EXPECT_THAT(ws[0].hint, HasSubstr("declared rate"));
}

TEST(RunWarnings, GyroBiasBeyondTheSpec) {
  fusion::EngineResult r = walk({});
  r.summary.imu_estimate.value.b_g = Eigen::Vector3d(0.0, -100.0 / 3600.0 * kDegToRad, 0.0);  // 100 °/h vs σ 20 °/h
  const auto ws = run_warnings(r, spec());
  ASSERT_EQ(codes(ws), std::vector<std::string>{"gyro_bias"});
  EXPECT_NEAR(ws[0].value, 100.0, 1e-6);
  EXPECT_NEAR(ws[0].limit, 60.0, 1e-6);
  r.summary.imu_estimate.value.b_g.y() = -50.0 / 3600.0 * kDegToRad;  // 2.5 σ: no warning
  EXPECT_TRUE(run_warnings(r, spec()).empty());
}

// Eq. 15.8: the first ZUPT of a stance beyond χ²₃(0.99) on more than 10 % of at least 10 stances.
TEST(RunWarnings, ZuptInnovationsBeyondTheirChiSquareBand) {
  fusion::EngineResult r = walk({});
  r.summary.zupt_first_of_stance = 40;
  r.summary.zupt_first_nis_above_p99 = 12;
  r.summary.zupt_first_nis_sum = 40 * 25.0;
  const auto ws = run_warnings(r, spec());
  ASSERT_EQ(codes(ws), std::vector<std::string>{"zupt_innovations"});
  EXPECT_NEAR(ws[0].value, 30.0, 1e-9);
  EXPECT_NEAR(ws[0].limit, 10.0, 1e-9);
  EXPECT_THAT(ws[0].message, HasSubstr("30.0 % of 40 stances"));
  EXPECT_THAT(ws[0].message, HasSubstr("mean NIS 25.0"));
  EXPECT_THAT(ws[0].hint, HasSubstr("zupt.sigma_mps"));
  r.summary.zupt_first_nis_above_p99 = 4;  // 10 %: at the limit, no warning
  EXPECT_TRUE(run_warnings(r, spec()).empty());
  r.summary.zupt_first_of_stance = 9;  // too few stances to judge
  r.summary.zupt_first_nis_above_p99 = 9;
  EXPECT_TRUE(run_warnings(r, spec()).empty());
}

}  // namespace
}  // namespace pednav::pipeline

namespace pednav::pipeline {
namespace {

// A foot IMU log in the engine's units: 200 Hz, at rest for 2 s, then 20 strides of 1.1 s whose swing turns the sole
// at up to 8 rad/s about y and accelerates it by up to 12 m/s² (| |f| − g | to 5.7 m/s²).
std::vector<ins::ImuSample> foot_log(double gyro_scale = 1.0, double time_scale = 1.0) {
  std::vector<ins::ImuSample> s;
  const double rate = 200.0;
  for (int k = 0; k < static_cast<int>(rate * 24.0); ++k) {
    const double t = k / rate, tw = t - 2.0;
    const double phase = tw >= 0.0 ? std::fmod(tw, 1.1) : 1.1;
    const double x = phase < 0.75 ? std::sin(kPi * phase / 0.75) : 0.0;
    ins::ImuSample m;
    m.t = GpsTime::from_ns(2300LL * kNsPerWeek + std::llround(t * time_scale * 1e9));
    m.omega_ib_b = gyro_scale * Eigen::Vector3d(0.01, 8.0 * x + 0.01, -0.01);
    m.f_ib_b = Eigen::Vector3d(12.0 * x, 0.0, -9.80665);
    s.push_back(m);
  }
  return s;
}

TEST(RunWarnings, AFootLogInItsDeclaredUnitsHasNoUnitWarning) {
  EXPECT_TRUE(imu_log_warnings(foot_log()).empty());
}

// °/s read as rad/s: the swing peaks at 458 "rad/s"; rad/s read as °/s: 0.14 rad/s while the accelerometer steps.
TEST(RunWarnings, GyroRatesNoFootProducesNameTheUnit) {
  const auto high = imu_log_warnings(foot_log(kRadToDeg));
  ASSERT_EQ(codes(high), std::vector<std::string>{"gyro_unit"});
  EXPECT_THAT(high[0].message, HasSubstr("gyro rates reach 45"));
  EXPECT_THAT(high[0].hint, HasSubstr("deg/s declared rad_per_s"));
  EXPECT_NEAR(high[0].value, 8.0 * kRadToDeg, 1.0);
  const auto low = imu_log_warnings(foot_log(kDegToRad));
  ASSERT_EQ(codes(low), std::vector<std::string>{"gyro_unit"});
  EXPECT_THAT(low[0].message, HasSubstr("the accelerometer shows steps"));
  EXPECT_THAT(low[0].hint, HasSubstr("rad/s declared deg_per_s"));
  EXPECT_NEAR(low[0].value, 8.0 * kDegToRad, 0.01);
}

// A time column in ms read as s: 0.2 Hz; in µs read as ms: 200 kHz.
TEST(RunWarnings, ASampleRateFromTheWrongTimeUnitIsNamed) {
  const auto slow = imu_log_warnings(foot_log(1.0, 1000.0));
  ASSERT_EQ(codes(slow), std::vector<std::string>{"imu_rate"});
  EXPECT_THAT(slow[0].message, HasSubstr("0.2 Hz from the time column"));
  EXPECT_NEAR(slow[0].value, 0.2, 1e-6);
  const auto fast = imu_log_warnings(foot_log(1.0, 1e-3));
  ASSERT_EQ(codes(fast), std::vector<std::string>{"imu_rate"});
  EXPECT_NEAR(fast[0].value, 2e5, 1.0);
}

}  // namespace
}  // namespace pednav::pipeline
