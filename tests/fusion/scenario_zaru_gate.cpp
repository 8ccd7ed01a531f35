// ZARU innovation gate (EngineOptions::zaru_gate_probability, docs/fusion.md §5.3). A foot that turns on the spot
// during a detected stance is at zero velocity but not at zero rate: a ZARU there tells the filter that the rotation
// is gyro bias. Here a level IMU rests 3 s (levelling window 0-2.5 s), then turns about its vertical at 0.3 rad/s for 3 s while every sample is
// labelled stance (zupt.detector labels). Without the gate the z-gyro bias estimate follows the turn; with it the
// ZARU rows are dropped (and counted) from the first turning interval on and the bias stays at its true value, 0.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/geodesy.hpp"
#include "fusion/engine.hpp"
#include "ins/imu_spec.hpp"

namespace pednav {
namespace {

constexpr double kRateHz = 200.0;
constexpr double kGravityMps2 = 9.80665;
constexpr double kTurnRadps = 0.3;
// True bias 0: with the gate the estimate stays within the prior's noise; without it it ends near the turn rate.
constexpr double kGatedBiasMax_radps = 0.005;
constexpr double kUngatedBiasMin_radps = 0.05;

struct GateRun {
  double bias_z_radps = 0.0;
  long zaru_updates = 0, zaru_rejected = 0;
};

GateRun run(double gate_probability) {
  std::vector<ins::ImuSample> imu;
  const GpsTime t0 = GpsTime::from_week_tow(2300, 100000.0);
  for (int i = 0; i < static_cast<int>(6.0 * kRateHz); ++i) {
    ins::ImuSample s;
    s.t = t0.plus_ns(static_cast<int64_t>(i) * 5'000'000);
    s.f_ib_b = Eigen::Vector3d(0.0, 0.0, -kGravityMps2);  // FRD body, level
    s.omega_ib_b = Eigen::Vector3d(0.0, 0.0, i >= 3.0 * kRateHz ? kTurnRadps : 0.0);
    imu.push_back(s);
  }
  // Every sample is stance except 0.1 s at 2.5 s: the levelling window (the first stance run) ends there.
  std::vector<uint8_t> labels(imu.size(), 1);
  for (int i = static_cast<int>(2.5 * kRateHz); i < static_cast<int>(2.6 * kRateHz); ++i) labels[i] = 0;
  fusion::EngineInputs in;
  in.imu = &imu;
  in.stance_labels = &labels;
  fusion::EngineOptions o;
  o.mode = fusion::Mode::kInsOnly;
  o.spec = *ins::imu_spec_preset("gx5_25");
  o.initial_position_e = ecef_from_geodetic(Geodetic{43.78 * kDegToRad, -79.47 * kDegToRad, 190.0});
  o.initial_yaw_rad = 0.0;
  o.zupt.detector = "labels";
  o.zaru_gate_probability = gate_probability;
  auto r = fusion::run_forward(in, o);
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
