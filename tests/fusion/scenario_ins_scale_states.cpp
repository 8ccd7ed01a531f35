// SPDX-License-Identifier: BSD-2-Clause
// Mode ins on an uncalibrated gyro (docs/consistency.md §3.16): the Crista's data-sheet gyro scale-factor σ is 1 %,
// so on datasets/indoor_loops (three corridor loops, 1080° of net turning) the unmodelled scale factors alone make
// ~10° of heading error by the end. `scale_factors.states: auto` gives mode ins the scale-factor states for such a
// sensor: the final error falls to ~0.2 % of the distance and the filter's yaw σ covers the yaw error. Fails if the
// auto rule is removed (states off: ~0.7 % and a yaw σ 3× too small).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/engine.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "io/scenario_config.hpp"
#include "sim/simulator.hpp"

namespace pednav {
namespace {

double yaw_n(const ins::NavState& x) {
  const Geodetic llh = geodetic_from_ecef(x.p_eb_e);
  return euler_from_R_n_b(R_e_n(llh.lat, llh.lon).transpose() * x.R_e_b()).z();
}

struct Final {
  double horizontal_m = 0.0;  ///< horizontal error at the last output epoch
  double yaw_err_rad = 0.0;
  double yaw_sd_rad = 0.0;    ///< the filter's yaw σ there
};

Final run_ins(const sim::Simulation& s, bool auto_scale_states) {
  io::RunConfig c;  // `pednav run` defaults for the scenario's sensor
  c.mode = "ins";
  c.imu.spec = s.scenario.imu.spec;
  c.smoother_enabled = false;
  if (!auto_scale_states) c.scale_factors.states = false;
  fusion::EngineOptions o = pipeline::engine_options(c);
  const ins::NavState& t0 = s.truth.nav.front();
  o.initial_position_e = t0.p_eb_e;
  o.initial_yaw_rad = yaw_n(t0);
  o.initial_sigma_pos_m = 0.01;
  o.initial_sigma_yaw_rad = 0.1 * kDegToRad;
  fusion::EngineInputs in;
  in.imu = &s.imu;
  auto r = fusion::run_forward(in, o);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  Final f;
  if (!r || r->epochs.empty()) return f;
  const fusion::EpochOutput& e = r->epochs.back();
  const long k = std::lround((e.t - s.truth.imu.front().t) * s.scenario.imu.rate_hz);
  EXPECT_GE(k, 0);
  EXPECT_LT(k, static_cast<long>(s.truth.nav.size()));
  if (k < 0 || k >= static_cast<long>(s.truth.nav.size())) return f;
  const ins::NavState& t = s.truth.nav[static_cast<size_t>(k)];
  const Geodetic llh = geodetic_from_ecef(t.p_eb_e);
  f.horizontal_m = (R_e_n(llh.lat, llh.lon).transpose() * (e.nav.p_eb_e - t.p_eb_e)).head<2>().norm();
  f.yaw_err_rad = std::remainder(yaw_n(e.nav) - yaw_n(t), 2.0 * kPi);
  f.yaw_sd_rad = e.sd_yaw_rad;
  return f;
}

// Measured 2026-12-05 (Release; seeds 41-60, 270 m each, at the last epoch): auto (states on) mean final error
// 0.202 % of the distance, RMS yaw error / RMS yaw σ 1.14; states off 0.698 %, 4.73 (100-seed Monte Carlo, median
// over the epochs of sample σ / filter σ of yaw: 0.99 vs 3.30, docs/consistency.md §3.16). Bounds: the figures with
// the states +25 % (an average of 20 deterministic runs; the margin covers another compiler or libm), the figures
// without them / 1.3 (the defect the states fix must stay visible). The yaw ratio's lower bound 0.8 is the
// consistency requirement (σ at most 25 % pessimistic), not a measured figure.
constexpr int kSeeds = 20;
constexpr double kDistanceM = 270.0;
constexpr double kMaxMeanPctWith = 0.202 * 1.25;
constexpr double kMinMeanPctWithout = 0.698 / 1.3;
constexpr double kYawRatioLo = 0.8, kYawRatioHi = 1.14 * 1.25;
constexpr double kMinYawRatioWithout = 4.73 / 1.3;

TEST(InsScaleStates, UncalibratedGyroGetsScaleStatesAndAnHonestYawSigma) {
  auto file = io::load_scenario("datasets/indoor_loops.yaml");
  ASSERT_TRUE(file.has_value()) << file.error().message;
  double sum_with = 0, sum_without = 0, e2_with = 0, v_with = 0, e2_without = 0, v_without = 0;
  for (int i = 0; i < kSeeds; ++i) {
    sim::Scenario sc = file->scenario;
    sc.seed += static_cast<uint64_t>(i);
    auto s = sim::simulate(sc);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    const Final w = run_ins(*s, true), wo = run_ins(*s, false);
    sum_with += w.horizontal_m;
    sum_without += wo.horizontal_m;
    e2_with += w.yaw_err_rad * w.yaw_err_rad;
    v_with += w.yaw_sd_rad * w.yaw_sd_rad;
    e2_without += wo.yaw_err_rad * wo.yaw_err_rad;
    v_without += wo.yaw_sd_rad * wo.yaw_sd_rad;
  }
  const double pct_with = 100.0 * sum_with / kSeeds / kDistanceM;
  const double pct_without = 100.0 * sum_without / kSeeds / kDistanceM;
  const double ratio_with = std::sqrt(e2_with / v_with), ratio_without = std::sqrt(e2_without / v_without);
  std::printf("[ ins scale states ] %d seeds: mean final error %.3f %% of %.0f m with, %.3f %% without; "
              "RMS yaw error / RMS yaw sigma %.2f with, %.2f without\n",
              kSeeds, pct_with, kDistanceM, pct_without, ratio_with, ratio_without);
  EXPECT_LT(pct_with, kMaxMeanPctWith);
  EXPECT_GT(pct_without, kMinMeanPctWithout);
  EXPECT_GT(ratio_with, kYawRatioLo);
  EXPECT_LT(ratio_with, kYawRatioHi);
  EXPECT_GT(ratio_without, kMinYawRatioWithout);
}

}  // namespace
}  // namespace pednav
