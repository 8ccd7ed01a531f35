// SPDX-License-Identifier: BSD-2-Clause
// ZARU innovation gate (EngineOptions::zaru_gate_probability, docs/fusion.md §5.3). A foot that turns on the spot
// during a detected stance is at zero velocity but not at zero rate: a ZARU there tells the filter that the rotation
// is gyro bias. Here a level IMU rests 3 s (levelling window 0-2.5 s), then turns about its vertical at 0.3 rad/s for 3 s while every sample is
// labelled stance (zupt.detector labels). Without the gate the z-gyro bias estimate follows the turn; with it the
// ZARU rows are dropped (and counted) from the first turning interval on and the bias stays at its true value, 0.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "tests/fusion/labelled_level_imu.hpp"

namespace pednav {
namespace {

constexpr double kTurnRadps = 0.3;
// True bias 0: with the gate the estimate stays within the prior's noise; without it it ends near the turn rate.
// Measured 2026-12-05 (Release, noise-free: deterministic): gated 5.045e-5 rad/s with 54 ZARU updates and 60 rejected,
// no gate 0.1268 rad/s with 114 ZARU updates. Bounds: the gated bias + 50 % (a small residual of the still part's
// ZARUs: relatively more sensitive to the operation order than the other figures), the ungated one / 1.3, counts
// ±3 (an interval on the gate's threshold may flip on another compiler).
constexpr double kGatedBiasMax_radps = 5.045e-5 * 1.5;
constexpr double kUngatedBiasMin_radps = 0.1268 / 1.3;
constexpr long kGatedZaru = 54, kGatedRejected = 60, kOpenZaru = 114, kCountTol = 3;

struct GateRun {
  double bias_z_radps = 0.0;
  long zaru_updates = 0, zaru_rejected = 0;
};

GateRun run(double gate_probability) {
  test::LabelledLevelImu log;  // every sample stance except 0.1 s at 2.5 s: the levelling window ends there
  log.rate_b = [](double t) { return Eigen::Vector3d(0.0, 0.0, t >= 3.0 ? kTurnRadps : 0.0); };
  fusion::EngineOptions o = test::labelled_level_imu_options();
  o.zaru_gate_probability = gate_probability;
  auto r = test::run_labelled_level_imu(log, o);
  EXPECT_TRUE(r) << r.error().message;
  GateRun g;
  if (!r) return g;
  g.bias_z_radps = r->summary.imu_estimate.value.b_g.z();
  g.zaru_updates = r->summary.zaru_updates;
  g.zaru_rejected = r->summary.zaru_rejected;
  return g;
}

TEST(ZaruGate, TurningOnTheSpotDuringStanceIsNotGyroBias) {
  const GateRun gated = run(0.999), open = run(0.0);
  std::printf("[zaru gate] z-gyro bias gated %.3e rad/s (%ld ZARU, %ld rejected), no gate %.4f rad/s (%ld ZARU, %ld rejected)\n",
              gated.bias_z_radps, gated.zaru_updates, gated.zaru_rejected, open.bias_z_radps, open.zaru_updates,
              open.zaru_rejected);
  EXPECT_LT(std::abs(gated.bias_z_radps), kGatedBiasMax_radps);
  EXPECT_GT(gated.zaru_rejected, 50);  // 3 s of turning at 20 Hz: (nearly) every turning interval
  EXPECT_GT(gated.zaru_updates, 30);   // the still part keeps its ZARUs
  EXPECT_NEAR(gated.zaru_rejected, kGatedRejected, kCountTol);
  EXPECT_NEAR(gated.zaru_updates, kGatedZaru, kCountTol);
  EXPECT_NEAR(open.zaru_updates, kOpenZaru, kCountTol);
  EXPECT_GT(open.bias_z_radps, kUngatedBiasMin_radps);
  EXPECT_EQ(open.zaru_rejected, 0);
}

}  // namespace
}  // namespace pednav
