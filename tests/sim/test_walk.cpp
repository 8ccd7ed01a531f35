// SPDX-License-Identifier: BSD-2-Clause
// Foot truth and IMU synthesis (sim/walk.*): the noise-free IMU written to imu.csv mechanizes back onto
// truth.csv; gait statistics match seed 004 (cycle, stance share) and the issue's pitch rates.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "ins/imu.hpp"
#include "ins/mechanization.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "pipeline/simulate_command.hpp"
#include "sim/simulator.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav {
namespace {

constexpr double kTolPos_m = 0.01;        // issue 4: within 1 cm over 10 min of walking
constexpr double kMinWalk_s = 600.0;      // the test walk must last 10 min
constexpr double kTolAtt_rad = 1e-5;
// Measured 2026-12-05 (Release): max position error 7.42e-4 m at 20 Hz and 7.44e-4 m at 100 Hz, attitude 7.08e-10 rad
// at both (the rounding of the CSV files and the integration of exact increments: deterministic), over a walk of
// 975 s and 1235 m. Bounds: the measured figures + 30 % beside the issue's 1 cm.
constexpr double kMeasuredPosMax_m = 7.44e-4 * 1.3;
constexpr double kMeasuredAttMax_rad = 7.08e-10 * 1.3;
constexpr double kWalkDuration_s = 975.0, kWalkDistance_m = 1235.0;

struct Row {
  GpsTime t;
  Eigen::Vector3d p_e, v_n, rpy_deg;
};

std::vector<Row> read_truth(const std::string& path) {
  std::vector<std::string> h;
  const auto rows = test::read_numeric_csv(path, &h);
  EXPECT_GE(h.size(), 18u);
  EXPECT_EQ(h[0], "gps_week");
  EXPECT_EQ(h[13], "yaw_deg");
  EXPECT_EQ(h[14], "ant_x_m");
  EXPECT_EQ(h[17], "stance");
  std::vector<Row> out;
  for (const auto& r : rows)
    out.push_back({GpsTime::from_week_tow(static_cast<int>(r[0]), r[1]), {r[5], r[6], r[7]}, {r[8], r[9], r[10]},
                   {r[11], r[12], r[13]}});
  return out;
}

ins::NavState state_of(const Row& r) {
  ins::NavState x;
  x.t = r.t;
  x.p_eb_e = r.p_e;
  const Geodetic llh = geodetic_from_ecef(r.p_e);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  x.v_eb_e = Ren * r.v_n;
  x.q_e_b = Eigen::Quaterniond(Ren * R_n_b_from_euler(r.rpy_deg.x() * kDegToRad, r.rpy_deg.y() * kDegToRad,
                                                      r.rpy_deg.z() * kDegToRad)).normalized();
  return x;
}

// Mechanize imu.csv at rate_hz from the first truth row; largest position error [m] and attitude error [rad].
void mechanize_against_truth(const std::string& dir, double rate_hz, double& max_pos_m, double& max_att_rad) {
  auto cfg = io::load_run_config(dir + "/config.yaml");
  ASSERT_TRUE(cfg.has_value()) << (cfg ? "" : cfg.error().message);
  auto log = io::read_imu_csv(cfg->imu.file, cfg->imu.format);
  ASSERT_TRUE(log.has_value()) << (log ? "" : log.error().message);
  const auto truth = read_truth(dir + "/truth.csv");
  ASSERT_EQ(truth.size(), log->samples.size());
  ASSERT_GE(truth.back().t - truth.front().t, kMinWalk_s);
  ins::NavState x = state_of(truth.front());
  ins::IncrementOptions opt;
  opt.rate_hz = rate_hz;
  ins::IncrementIntegrator integ(opt);
  max_pos_m = max_att_rad = 0.0;
  const int64_t dt_ns = truth[1].t.ns() - truth[0].t.ns();
  for (const auto& s : log->samples) {
    integ.push(s, [&](const ins::ImuIncrement& inc) {
      x = ins::mechanize(x, inc);
      const auto k = static_cast<size_t>((x.t.ns() - truth.front().t.ns()) / dt_ns);
      const ins::NavState tr = state_of(truth[k]);
      max_pos_m = std::max(max_pos_m, (x.p_eb_e - tr.p_eb_e).norm());
      max_att_rad = std::max(max_att_rad, so3_log(tr.R_e_b().transpose() * x.R_e_b()).norm());
    });
  }
}

class NoiseFreeWalk : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::temp_dir("noise_free_walk");
    auto sum = pipeline::run_simulate_command(test::scenario_from_text(test::kNoiseFreeWalkYaml), dir_);
    ASSERT_TRUE(sum.has_value()) << (sum ? "" : sum.error().message);
    summary_ = *sum;
  }
  static inline std::string dir_;
  static inline pipeline::SimulateSummary summary_;
};

TEST_F(NoiseFreeWalk, MechanizedImuCsvStaysOnTruthCsvAt20Hz) {
  double pos = 0, att = 0;
  mechanize_against_truth(dir_, 20.0, pos, att);
  EXPECT_LT(pos, kTolPos_m);
  EXPECT_LT(att, kTolAtt_rad);
  EXPECT_LT(pos, kMeasuredPosMax_m);
  EXPECT_LT(att, kMeasuredAttMax_rad);
  EXPECT_NEAR(summary_.duration_s, kWalkDuration_s, 1.0);
  EXPECT_NEAR(summary_.distance_m, kWalkDistance_m, 0.01 * kWalkDistance_m);
  std::printf("noise-free walk %.0f s, %.0f m: max position error at 20 Hz %.2e m, attitude %.2e rad\n",
              summary_.duration_s, summary_.distance_m, pos, att);
}

TEST_F(NoiseFreeWalk, MechanizedImuCsvStaysOnTruthCsvAtImuRate) {
  double pos = 0, att = 0;
  mechanize_against_truth(dir_, 100.0, pos, att);
  EXPECT_LT(pos, kTolPos_m);
  EXPECT_LT(att, kTolAtt_rad);
  EXPECT_LT(pos, kMeasuredPosMax_m);
  EXPECT_LT(att, kMeasuredAttMax_rad);
  std::printf("max position error at 100 Hz %.2e m, attitude %.2e rad\n", pos, att);
}

TEST(Walk, GaitMatchesSeed004AndIssueRates) {
  auto sc = test::scenario_from_text(test::kNoiseFreeWalkYaml);
  auto sim = sim::simulate(sc.scenario);
  ASSERT_TRUE(sim.has_value()) << (sim ? "" : sim.error().message);
  const auto& plan = sim->plan;
  ASSERT_GT(plan.strides.size(), 800u);  // 865 strides (measured 2026-12-05)
  double stance_sum = 0, cycle_sum = 0;
  int n = 0;
  for (size_t i = 0; i + 1 < plan.strides.size(); ++i) {
    const auto& s = plan.strides[i];
    const double cycle = plan.strides[i + 1].t_lift_s - s.t_lift_s;
    if (cycle > 2.0) continue;  // pause
    cycle_sum += cycle;
    stance_sum += s.stance_s / cycle;
    ++n;
  }
  // Measured 2026-12-05 (the plan and the truth are deterministic): 864 cycles of 1.0998 s mean, stance share 0.3000,
  // peak pitch rate 9.300 rad/s, max truth speed in stance 8.07e-4 m/s, end 5.1000 m north, 0.0001 m east of the
  // origin. Bounds: the configured cycle and stance share within 0.2 % / 0.002 (the plan rounds to IMU samples), the
  // peak pitch rate ±3 % beside the issue's 6-10 rad/s, the stance speed + 25 % (below the issue's 1 mm/s), the end
  // point within 1 cm of the last waypoint + the foot offset.
  EXPECT_NEAR(cycle_sum / n, 1.1, 0.002 * 1.1);  // configured cycle
  EXPECT_NEAR(stance_sum / n, 0.30, 0.002);      // configured stance share (seed 004: ~25 %)
  double peak_pitch_rate = 0;
  for (const auto& m : sim->truth.imu) peak_pitch_rate = std::max(peak_pitch_rate, std::abs(m.omega_ib_b.y()));
  EXPECT_GT(peak_pitch_rate, 6.0);   // issue 4: pitch rates up to ~7 rad/s
  EXPECT_LT(peak_pitch_rate, 10.0);
  EXPECT_NEAR(peak_pitch_rate, 9.300, 0.03 * 9.300);
  // Stance: the foot is still (truth velocity below 1 mm/s) and level.
  double max_stance_speed = 0;
  for (size_t k = 0; k < sim->truth.nav.size(); ++k)
    if (sim->truth.stance[k]) max_stance_speed = std::max(max_stance_speed, sim->truth.nav[k].v_eb_e.norm());
  EXPECT_LT(max_stance_speed, 1e-3);
  EXPECT_LT(max_stance_speed, 1.25 * 8.07e-4);
  // The plan lands on the route's end point: n of the last waypoint (5 m) + the default foot offset 0.1 m to the
  // right of the walking line (north when west-bound).
  const Eigen::Vector3d end_n0 = sim->frame.to_n0(sim->truth.nav.back().p_eb_e);
  EXPECT_NEAR(end_n0.x(), 5.0 + 0.1, 0.01);
  EXPECT_NEAR(end_n0.y(), 0.0, 0.01);
  EXPECT_EQ(n, 864);
  std::printf("[gait] %d cycles: mean %.4f s, stance share %.4f; peak pitch rate %.3f rad/s; max stance speed %.3e "
              "m/s; end n0 %+.4f %+.4f m\n",
              n, cycle_sum / n, stance_sum / n, peak_pitch_rate, max_stance_speed, end_n0.x(), end_n0.y());
}

TEST(Walk, NoRouteIsAnError) {
  auto sc = io::parse_scenario("seed: 1\nstart: {gps_week: 2300, gps_tow_s: 0}\norigin: {lat_deg: 1, lon_deg: 2}\n"
                               "route: {static_start_s: 1}\nbogus_key: 3\n",
                               "bad.yaml", ".");
  ASSERT_FALSE(sc.has_value());
  EXPECT_NE(sc.error().message.find("route.waypoints: required key is missing"), std::string::npos) << sc.error().message;
  EXPECT_NE(sc.error().message.find("bogus_key"), std::string::npos) << sc.error().message;
}

}  // namespace
}  // namespace pednav
