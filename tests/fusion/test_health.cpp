// SPDX-License-Identifier: BSD-2-Clause
// Filter health: a diverging run is a reported failure, never a confident absurd trajectory (issue 5/11).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/geodesy.hpp"
#include "fusion/engine.hpp"
#include "fusion/health.hpp"
#include "ins/imu_spec.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"

namespace pednav {
namespace {

using ::testing::HasSubstr;

constexpr double kRateHz = 100.0;
constexpr double kGravityMps2 = 9.80665;
constexpr double kStillS = 5.0;               // level, still start (the engine levels here)
constexpr double kPushMps2 = 30.0;            // then a constant horizontal specific force no foot sustains
constexpr double kDurationS = 15.0;           // 10 s of it: 300 m/s, far beyond the 100 m/s plausibility bound

TEST(EngineHealth, ImplausibleSpeedIsReportedAsDivergence) {
  std::vector<ins::ImuSample> imu;
  const GpsTime t0 = GpsTime::from_week_tow(2300, 1000.0);
  for (int i = 0; i < static_cast<int>(kDurationS * kRateHz); ++i) {
    ins::ImuSample s;
    s.t = t0.plus_ns(static_cast<int64_t>(i) * 10'000'000);
    s.f_ib_b = Eigen::Vector3d(0.0, 0.0, -kGravityMps2);  // FRD body, level
    if (i >= kStillS * kRateHz) s.f_ib_b.x() = kPushMps2;
    imu.push_back(s);
  }
  fusion::EngineInputs in;
  in.imu = &imu;
  fusion::EngineOptions o;
  o.mode = fusion::Mode::kInsOnly;
  o.initial_position_e = ecef_from_geodetic(Geodetic{0.9, 0.1, 100.0});
  o.initial_yaw_rad = 0.0;
  o.spec = *ins::imu_spec_preset("crista");
  auto r = fusion::run_forward(in, o);
  ASSERT_FALSE(r) << "a 300 m/s foot must not come out as a healthy trajectory";
  EXPECT_THAT(r.error().message, HasSubstr("filter diverged at"));
  EXPECT_THAT(r.error().message, HasSubstr("a walking person stays below 100 m/s"));
}

// The covariance check of the health test (fusion/health.hpp): a healthy P passes; asymmetry, indefiniteness and
// non-finite entries are named.
TEST(EngineHealth, CovarianceDefectsAreNamed) {
  constexpr int kDim = 17;
  ins::ErrorMatrix P = ins::ErrorMatrix::Identity(kDim, kDim);
  P.block<3, 3>(0, 0) *= 1e4;  // position [m²] next to attitude [rad²]: the check works on correlations
  P.block<3, 3>(6, 6) *= 1e-6;
  P(0, 6) = P(6, 0) = 0.9 * std::sqrt(P(0, 0) * P(6, 6));  // a strong but valid correlation
  EXPECT_EQ(fusion::covariance_defect(P), nullptr);
  ins::ErrorMatrix A = P;
  A(1, 2) += 1e-6 * A(0, 0);  // relative asymmetry 1e-6 > kMaxRelativeAsymmetry
  ASSERT_NE(fusion::covariance_defect(A), nullptr);
  EXPECT_THAT(fusion::covariance_defect(A), HasSubstr("not symmetric"));
  ins::ErrorMatrix N = P;
  N(0, 6) = N(6, 0) = 1.5 * std::sqrt(P(0, 0) * P(6, 6));  // a correlation of 1.5: no covariance has it
  ASSERT_NE(fusion::covariance_defect(N), nullptr);
  EXPECT_THAT(fusion::covariance_defect(N), HasSubstr("not positive semi-definite"));
  ins::ErrorMatrix F = P;
  F(3, 3) = std::numeric_limits<double>::quiet_NaN();
  ASSERT_NE(fusion::covariance_defect(F), nullptr);
  EXPECT_THAT(fusion::covariance_defect(F), HasSubstr("non-finite"));
}

TEST(EngineHealth, RunWithoutImuFormatIsAConfigError) {
  // The spec may be left out (the log calibrates itself); the format may not.
  auto cfg = io::parse_run_config("mode: ins\nimu:\n  file: imu.csv\n", "run.yaml", "/nonexistent");
  ASSERT_TRUE(cfg) << cfg.error().message;
  auto r = pipeline::run_run_command(*cfg, ::testing::TempDir() + "pednav_health_out");
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("run.yaml: imu.format: required for pednav run"));
}

}  // namespace
}  // namespace pednav
