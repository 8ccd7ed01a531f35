// SPDX-License-Identifier: BSD-2-Clause
// The hand-held carry of the simulator (sim/hand.cpp, docs/sim.md §9): the truth of a device held in front of the
// walker (the mechanization of its exact samples) follows the designed hand track, it never swings like a foot and is
// at rest only when it is, it faces along the walk, and its GNSS antenna is its own.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>
#include <cmath>
#include <string>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "sim/simulator.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav {
namespace {

// The noise-free walk of the foot tests with the IMU in the hand.
sim::Scenario hand_walk() {
  std::string y = test::kNoiseFreeWalkYaml;
  const std::string foot = "imu: {rate_hz: 100, spec: crista, errors: false}";
  y.replace(y.find(foot), foot.size(), "imu: {rate_hz: 100, spec: crista, errors: false, carry: hand}");
  return test::scenario_from_text(y).scenario;
}

// Measured 2026-12-06 (Release), this 975-s walk: the truth (the mechanization of the exact samples) stays within
// 9.7e-5 m of the designed hand track (the samples' central differences over ±1 ms and the tracking feedback), rates
// above 2 rad/s on 0.08 % of the samples (the U-turns; peak 2.96 rad/s), the device's heading off the walking
// direction by 3.9° at the median (its sideways sway and yaw swing) and 23.6° at the 99th percentile (the corners: the
// heading turns over a second, and around a corner the hand's own velocity points sideways). Bounds: measured + 50 %,
// the rate share also below the engine's 0.5 % (a foot: ~30 %).
constexpr double kMaxTracking_m = 9.7e-5 * 1.5;
constexpr double kMaxFastShare = 0.0008 * 1.5;
constexpr double kMaxFacingP99_rad = 23.6 * kDegToRad * 1.5, kMaxFacingMedian_rad = 3.9 * kDegToRad * 1.5;

TEST(HandCarry, TheTruthFollowsTheHandAndNeverSwingsLikeAFoot) {
  auto s = sim::simulate(hand_walk());
  ASSERT_TRUE(s) << s.error().message;
  const auto& nav = s->truth.nav;
  const auto& imu = s->truth.imu;
  ASSERT_EQ(nav.size(), imu.size());
  size_t fast = 0;
  double peak = 0.0;
  for (const auto& m : imu) {
    peak = std::max(peak, m.omega_ib_b.norm());
    fast += m.omega_ib_b.norm() > 2.0;
  }
  const double fast_share = static_cast<double>(fast) / static_cast<double>(imu.size());
  // The GNSS antenna is the device's: the antenna truth is the hand's design, which the IMU truth tracks.
  ASSERT_EQ(s->antenna.size(), nav.size());
  double tracking = 0.0;
  for (size_t k = 0; k < nav.size(); ++k) tracking = std::max(tracking, (s->antenna[k].p_e - nav[k].p_eb_e).norm());
  std::printf("[hand carry] rates above 2 rad/s on %.2f %% of the samples (peak %.2f rad/s); truth vs designed hand "
              "track: worst %.2e m\n",
              100.0 * fast_share, peak, tracking);
  EXPECT_LT(fast_share, 0.005);
  EXPECT_LT(fast_share, kMaxFastShare);
  EXPECT_LT(tracking, kMaxTracking_m);
}

TEST(HandCarry, AtRestOnlyWhenTheDeviceIsAndFacesAlongTheWalk) {
  auto s = sim::simulate(hand_walk());
  ASSERT_TRUE(s) << s.error().message;
  const auto& nav = s->truth.nav;
  size_t moving = 0, moving_stance = 0, rest = 0, rest_but_moving = 0;
  std::vector<double> facing;
  for (size_t k = 0; k < nav.size(); ++k) {
    const Geodetic llh = geodetic_from_ecef(nav[k].p_eb_e);
    const Eigen::Vector3d v_n = R_e_n(llh.lat, llh.lon).transpose() * nav[k].v_eb_e;
    const double speed = v_n.head<2>().norm();
    if (s->truth.stance[k]) {
      ++rest;
      rest_but_moving += nav[k].v_eb_e.norm() > 1e-2;
    }
    if (speed > 0.5) {
      ++moving;
      moving_stance += s->truth.stance[k];
      const double yaw = euler_from_R_n_b(R_e_n(llh.lat, llh.lon).transpose() * nav[k].R_e_b()).z();
      facing.push_back(std::abs(std::remainder(yaw - std::atan2(v_n.y(), v_n.x()), 2.0 * kPi)));
    }
  }
  EXPECT_GT(moving, 50000u);
  EXPECT_EQ(moving_stance, 0u);
  EXPECT_GT(rest, 1000u);  // the static start, the end and the pause
  EXPECT_EQ(rest_but_moving, 0u);
  std::sort(facing.begin(), facing.end());
  const double p99 = facing[facing.size() * 99 / 100], median = facing[facing.size() / 2];
  std::printf("[hand carry] heading off the walking direction: median %.1f deg, 99th percentile %.1f deg\n",
              median * kRadToDeg, p99 * kRadToDeg);
  EXPECT_LT(p99, kMaxFacingP99_rad);
  EXPECT_LT(median, kMaxFacingMedian_rad);
}

TEST(HandCarry, ACarryThatIsNeitherFootNorHandIsNamed) {
  sim::Scenario sc = hand_walk();
  sc.imu.carry = "pocket";
  auto s = sim::simulate(sc);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("imu.carry: expected foot or hand, got 'pocket'"), std::string::npos)
      << s.error().message;
  // The along-a-track mode gives the antenna's track, not a walker's body: no hand to carry the device.
  sc.imu.carry = "hand";
  sc.track.resize(2);
  sc.track[1].t = sc.track[0].t.plus_s(1.0);
  const auto problems = sc.problems();
  EXPECT_NE(std::find(problems.begin(), problems.end(), "imu.carry: hand needs a route (not the along-a-track mode)"),
            problems.end());
}

}  // namespace
}  // namespace pednav
