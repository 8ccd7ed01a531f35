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
constexpr double kGatedBiasMax_radps = 0.005;
constexpr double kUngatedBiasMin_radps = 0.05;

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
  std::printf("[zaru gate] z-gyro bias gated %.4f rad/s (%ld ZARU, %ld rejected), no gate %.4f rad/s (%ld ZARU)\n",
              gated.bias_z_radps, gated.zaru_updates, gated.zaru_rejected, open.bias_z_radps, open.zaru_updates);
  EXPECT_LT(std::abs(gated.bias_z_radps), kGatedBiasMax_radps);
  EXPECT_GT(gated.zaru_rejected, 50);  // 3 s of turning at 20 Hz: (nearly) every turning interval
  EXPECT_GT(gated.zaru_updates, 30);   // the still part keeps its ZARUs
  EXPECT_GT(open.bias_z_radps, kUngatedBiasMin_radps);
  EXPECT_EQ(open.zaru_rejected, 0);
}

}  // namespace
}  // namespace pednav
