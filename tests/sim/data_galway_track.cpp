// SPDX-License-Identifier: BSD-2-Clause
// Along-a-track mode on the real Galway walk (datasets/galway_track.yaml): the synthesized foot IMU is aligned in
// GPST with the real GNSS, the foot truth follows the RTK track, and the written config.yaml runs `pednav gnss`
// on the REAL rover/base/nav files with the GGA track as reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>

#include "eval/statistics.hpp"
#include "eval/trajectory.hpp"
#include "core/geodesy.hpp"
#include "fusion/ambiguity.hpp"
#include "fusion/engine.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "io/scenario_config.hpp"
#include "pipeline/simulate_command.hpp"
#include "io/trajectory_io.hpp"
#include "tests/sim/fixtures.hpp"
#include "tests/support/data.hpp"

namespace pednav {
namespace {

// Figures measured 2026-12-06 (Release build; the planner of docs/sim.md §3 whose strides keep up with the track);
// bounds +20 % (kMargin: another libm/compiler) unless said otherwise.
constexpr double kMargin = 1.20;
// Foot under the walker vs the antenna track (the stride phase, the foot's 0.1-m lateral offset and the 0.5-s
// Gaussian smoothing of the track): measured 0.14 m RMS over 53419 epochs (0.85 m with the 1-s kernel and in-place
// turning strides, where the foot fell metres behind at corners).
constexpr double kFootToTrackRms_m = 0.14;
constexpr int kFootToTrackEpochs = 53419;
// Tightly coupled run on the real M8P GNSS (issue 5: forward 2D RMS <= 1.5 m, max <= 5 m, 100 % availability against
// the RTK-fixed GGA epochs; issue 6: smoothed 2D RMS <= 1.0 m). Measured: forward 0.73 m / 2.14 m over 551 epochs,
// smoothed 0.43 m / 1.03 m.
constexpr double kMaxForwardRms_m = 1.5;
constexpr double kMaxForwardMax_m = 5.0;
constexpr double kMinAvailabilityPct = 100.0 - 1e-9;
constexpr double kMaxSmoothedRms_m = 1.0;
constexpr double kForwardRms_m = 0.73, kForwardMax_m = 2.14, kSmoothedRms_m = 0.43, kSmoothedMax_m = 1.03;
constexpr int kForwardEpochs = 551;
// Honesty of σ on real signals: share of 1 Hz epochs with |e_N| <= 3σ_N and |e_E| <= 3σ_E against the simulated
// foot truth. What a consistent filter gives here: if the errors were only those of the filter's model, Gaussian,
// (0.9973)² = 99.5 % on both axes. But the GNSS signals are the real antenna's, on the GGA track, while the IMU is
// the synthesized foot, 0.14 m RMS from that track (FootImuAlongTheRealRtkTrack: the stride phase — the foot stands
// while the walker moves on — and the smoothed track the foot was planned on). The filter's measurement model
// (antenna = stride-averaged foot + lever arm) does not contain that discrepancy, so a forward solution that follows
// the GNSS carries it into its foot error while its σ does not: the share falls below 99.5 % by roughly the share of
// epochs where a discrepancy of that size exceeds the 3σ margin left by the filter's own error. The smoother
// averages the stride-phase part (zero mean over a stride) out and gets close to the consistent figure. So: forward
// well below 99.5 %, smoothed near it. Measured: forward 82.2 %, smoothed 100.0 % (75.0 / 98.5 % with the foot
// 0.85 m off the track; with white code errors, multipath.states: false, 29.9 % / 21.1 % when the test was written,
// so the bounds fail without the states). Bounds on the share OUTSIDE 3σ: forward measured +20 % (17.8 % -> 21.4 %);
// smoothed 0 % measured, bounded by 1 % (twice the 0.5 % a consistent filter leaves outside on both axes).
constexpr double kMinForwardInside3SigmaPct = 100.0 - kMargin * 17.8;
constexpr double kMinSmoothedInside3SigmaPct = 100.0 - 1.0;

TEST(GalwayTrack, FootImuAlongTheRealRtkTrack) {
  const std::string nmea = test::shared_data("gnss_ublox_m8p_walk_galway/reference_nmea/rover-20181004-1532.nmea");
  PEDNAV_REQUIRE_DATA(nmea);
  auto sc = io::load_scenario(test::source_path("datasets/galway_track.yaml"));
  ASSERT_TRUE(sc.has_value()) << (sc ? "" : sc.error().message);
  const std::string dir = test::temp_dir("galway_track");
  auto sum = pipeline::run_simulate_command(*sc, dir);
  ASSERT_TRUE(sum.has_value()) << (sum ? "" : sum.error().message);
  EXPECT_GT(sum->strides, 150);
  EXPECT_EQ(sum->rover_epochs, 0);  // the GNSS is the real one

  auto cfg = io::load_run_config(dir + "/config.yaml");
  ASSERT_TRUE(cfg.has_value()) << (cfg ? "" : cfg.error().message);
  EXPECT_NE(cfg->gnss.rover_obs.find("rover-20181004-1532.obs"), std::string::npos);
  EXPECT_EQ(cfg->reference.format, "nmea");

  io::TrajectoryReadOptions fixed;
  fixed.nmea_qualities = {4};
  auto ref = io::read_trajectory(nmea, fixed);
  auto foot = io::read_trajectory(dir + "/truth.csv", {});
  ASSERT_TRUE(ref && foot);
  // GPST alignment: the IMU starts on the first whole second of the track.
  const GpsTime t_imu = foot->trajectory.points.front().t;
  EXPECT_EQ(t_imu.ns() % kNsPerS, 0);
  EXPECT_LT(t_imu - ref->trajectory.points.front().t, 60.0);
  auto ev = eval::compare(foot->trajectory, ref->trajectory, {});
  ASSERT_TRUE(ev.has_value()) << (ev ? "" : ev.error().message);
  std::printf("galway_track: foot truth vs RTK-fixed GGA: %d epochs, horizontal RMS %.2f m\n", ev->epochs_compared,
              ev->horizontal_rms_m);
  EXPECT_NEAR(ev->epochs_compared, kFootToTrackEpochs, 0.01 * kFootToTrackEpochs);
  EXPECT_LT(ev->horizontal_rms_m, kMargin * kFootToTrackRms_m);
}

TEST(GalwayTrack, TightlyCoupledOnTheRealGnssAgainstRtkFixed) {
  const std::string nmea = test::shared_data("gnss_ublox_m8p_walk_galway/reference_nmea/rover-20181004-1532.nmea");
  PEDNAV_REQUIRE_DATA(nmea);
  auto sc = io::load_scenario(test::source_path("datasets/galway_track.yaml"));
  ASSERT_TRUE(sc.has_value()) << (sc ? "" : sc.error().message);
  const std::string dir = test::temp_dir("galway_track_tc");
  auto sum = pipeline::run_simulate_command(*sc, dir);
  ASSERT_TRUE(sum.has_value()) << (sum ? "" : sum.error().message);
  auto cfg = io::load_run_config(dir + "/config.yaml");
  ASSERT_TRUE(cfg.has_value()) << (cfg ? "" : cfg.error().message);
  cfg->mode = "tc";
  auto data = pipeline::load_run_inputs(*cfg);
  ASSERT_TRUE(data.has_value()) << (data ? "" : data.error().message);
  auto r = fusion::run_forward(data->engine_inputs(), data->options);
  ASSERT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  ASSERT_TRUE(r->summary.smoothed);

  io::TrajectoryReadOptions fixed;
  fixed.nmea_qualities = {4};
  auto ref = io::read_trajectory(nmea, fixed);
  auto foot = io::read_trajectory(dir + "/truth.csv", {});
  ASSERT_TRUE(ref && foot);
  auto as_trajectory = [](const std::vector<fusion::EpochOutput>& epochs) {
    eval::Trajectory t;
    for (const auto& e : epochs) {
      const Eigen::Vector3d sd_enu(std::sqrt(e.cov_p_n(1, 1)), std::sqrt(e.cov_p_n(0, 0)), std::sqrt(e.cov_p_n(2, 2)));
      t.points.push_back({e.t, e.nav.p_eb_e, sd_enu});
    }
    return t;
  };
  auto fwd = eval::compare(as_trajectory(r->epochs), ref->trajectory, {});
  auto smo = eval::compare(as_trajectory(r->smoothed), ref->trajectory, {});
  ASSERT_TRUE(fwd && smo);
  // 3σ share against the foot truth (100 Hz; the 1 Hz epochs fall on its samples).
  auto inside3_pct = [&](const std::vector<fusion::EpochOutput>& epochs) {
    auto ev = eval::compare(as_trajectory(epochs), foot->trajectory, {});
    EXPECT_TRUE(ev.has_value());
    const eval::ConsistencyStats c = ev ? eval::consistency_statistics(ev->errors) : eval::ConsistencyStats{};
    EXPECT_GT(c.epochs, 1000);
    return c.inside_3sigma_pct;
  };
  const double in_f = inside3_pct(r->epochs), in_s = inside3_pct(r->smoothed);
  std::printf("galway_track tc vs RTK-fixed GGA: forward %d epochs, RMS %.2f m, max %.2f m, availability %.1f %%; "
              "smoothed RMS %.2f m, max %.2f m; inside 3 sigma (foot truth): forward %.1f %%, smoothed %.1f %%\n",
              fwd->epochs_compared, fwd->horizontal_rms_m, fwd->horizontal_max_m, fwd->availability_pct,
              smo->horizontal_rms_m, smo->horizontal_max_m, in_f, in_s);
  EXPECT_LE(fwd->horizontal_rms_m, kMaxForwardRms_m);
  EXPECT_LE(fwd->horizontal_max_m, kMaxForwardMax_m);
  EXPECT_GE(fwd->availability_pct, kMinAvailabilityPct);
  EXPECT_LE(smo->horizontal_rms_m, kMaxSmoothedRms_m);
  EXPECT_NEAR(fwd->epochs_compared, kForwardEpochs, 0.01 * kForwardEpochs);
  EXPECT_LT(fwd->horizontal_rms_m, kMargin * kForwardRms_m);
  EXPECT_LT(fwd->horizontal_max_m, kMargin * kForwardMax_m);
  EXPECT_LT(smo->horizontal_rms_m, kMargin * kSmoothedRms_m);
  EXPECT_LT(smo->horizontal_max_m, kMargin * kSmoothedMax_m);
  // Issue 49 item 4 (the other committed scenarios: tests/pipeline/scenario_smoothed_vs_forward.cpp).
  EXPECT_LE(smo->horizontal_rms_m, fwd->horizontal_rms_m) << "the smoothed solution is worse than the forward one";
  EXPECT_GE(in_f, kMinForwardInside3SigmaPct);
  EXPECT_GE(in_s, kMinSmoothedInside3SigmaPct);
}

// galway_track simulated into a fresh folder and run in mode tc with `edit` applied to its written config.yaml.
std::optional<fusion::EngineResult> run_galway_track(const std::string& name,
                                                      const std::function<void(io::RunConfig&)>& edit) {
  auto sc = io::load_scenario(test::source_path("datasets/galway_track.yaml"));
  EXPECT_TRUE(sc.has_value()) << (sc ? "" : sc.error().message);
  if (!sc) return std::nullopt;
  const std::string dir = test::temp_dir(name);
  if (!pipeline::run_simulate_command(*sc, dir).has_value()) return std::nullopt;
  auto cfg = io::load_run_config(dir + "/config.yaml");
  EXPECT_TRUE(cfg.has_value()) << (cfg ? "" : cfg.error().message);
  if (!cfg) return std::nullopt;
  cfg->mode = "tc";
  edit(*cfg);
  auto data = pipeline::load_run_inputs(*cfg);
  EXPECT_TRUE(data.has_value()) << (data ? "" : data.error().message);
  if (!data) return std::nullopt;
  auto r = fusion::run_forward(data->engine_inputs(), data->options);
  EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message);
  if (!r) return std::nullopt;
  return std::move(*r);
}

// Carrier phase in the tight coupling on the real Galway walk (issue 48, docs/carrier.md §8): `pednav run` with
// gnss.carrier: on and the peer configuration of ../shared/notes/rtk_peer_galway.md (G+R, 15°, 35 dB-Hz; rover and
// base are both M8P, so GLONASS is fixed too), scored on the antenna output (antenna.csv) against the receiver's
// fixed GGA epochs. Measured 2026-12-06 (Release): 685 of 1171 output epochs fixed; 407 of them have a receiver-fixed
// epoch, none is > 0.10 m from it, RMS 0.012 m on them; over all 551 receiver-fixed epochs forward 0.293 m (the first
// 100 s before the first fix: 2.97 m at most), smoothed 0.016 m (forward 0.365 m without eq. M.2a's GLONASS
// multipath σ; with 4 double differences at least instead of the default 6: 716 fixed, 2 of 425 wrong). Bounds: fixed
// −5 %, wrong +2, RMS +20 %.
namespace carrier {
constexpr int kFixed = 685, kFixedScored = 407, kWrong = 0;
constexpr double kRmsOnFixed_m = 0.012, kForwardRms_m = 0.293, kSmoothedRms_m = 0.016;
}  // namespace carrier

TEST(GalwayTrack, CarrierInTheTightCouplingFixesTheRealPhase) {
  const std::string nmea = test::shared_data("gnss_ublox_m8p_walk_galway/reference_nmea/rover-20181004-1532.nmea");
  PEDNAV_REQUIRE_DATA(nmea);
  const auto r = run_galway_track("galway_track_carrier", [](io::RunConfig& c) {
    c.gnss.carrier = "on";
    c.gnss.systems = {"G", "R"};
    c.gnss.elevation_mask_rad = 15.0 * kDegToRad;
    c.gnss.min_cn0_dbhz = 35.0;
    c.gnss.ambiguity.glonass = true;
  });
  ASSERT_TRUE(r.has_value());
  ASSERT_TRUE(r->summary.smoothed);

  io::TrajectoryReadOptions fixed;
  fixed.nmea_qualities = {4};
  auto ref = io::read_trajectory(nmea, fixed);
  ASSERT_TRUE(ref.has_value());
  auto antenna = [](const std::vector<fusion::EpochOutput>& epochs) {
    eval::Trajectory t;
    for (const auto& e : epochs) {
      if (!e.has_antenna) continue;
      const Eigen::Matrix3d& c = e.cov_ant_p_n;
      t.points.push_back({e.t, e.ant_p_e, Eigen::Vector3d(std::sqrt(c(1, 1)), std::sqrt(c(0, 0)), std::sqrt(c(2, 2)))});
    }
    return t;
  };
  auto fwd = eval::compare(antenna(r->epochs), ref->trajectory, {});
  auto smo = eval::compare(antenna(r->smoothed), ref->trajectory, {});
  ASSERT_TRUE(fwd && smo);
  // The forward status of the output epoch nearest each reference epoch (the GNSS epochs are at .987 s).
  auto status_at = [&](GpsTime t) {
    const auto it = std::lower_bound(r->epochs.begin(), r->epochs.end(), t,
                                     [](const fusion::EpochOutput& e, GpsTime q) { return e.t < q; });
    int best = 0;
    double best_dt = 0.5;
    for (auto j = it == r->epochs.begin() ? it : it - 1; j != r->epochs.end() && j <= it; ++j) {
      if (std::abs(j->t - t) < best_dt) best_dt = std::abs(j->t - t), best = j->solution_status;
    }
    return best;
  };
  int fixed_epochs = 0, scored = 0, wrong = 0;
  for (const auto& e : r->epochs) fixed_epochs += e.solution_status == static_cast<int>(fusion::SolutionStatus::kFixed);
  std::vector<double> on_fixed;
  for (const auto& e : fwd->errors) {
    if (status_at(e.t) != static_cast<int>(fusion::SolutionStatus::kFixed)) continue;
    ++scored;
    wrong += e.horizontal_m > 0.10;
    on_fixed.push_back(e.horizontal_m);
  }
  double sum_sq = 0.0;
  for (double h : on_fixed) sum_sq += h * h;
  const double rms_on_fixed = on_fixed.empty() ? 0.0 : std::sqrt(sum_sq / static_cast<double>(on_fixed.size()));
  std::printf("galway_track tc with carrier (antenna): %d fixed epochs, %d with a receiver-fixed epoch, %d wrong "
              "(> 0.10 m), RMS on them %.3f m; over the receiver's %d fixed epochs forward %.3f m, smoothed %.3f m\n",
              fixed_epochs, scored, wrong, rms_on_fixed, fwd->epochs_compared, fwd->horizontal_rms_m,
              smo->horizontal_rms_m);
  EXPECT_GE(fixed_epochs, 552);  // issue 48: at least the receiver's own real-time count
  EXPECT_GE(fixed_epochs, carrier::kFixed - 34);
  EXPECT_GE(scored, carrier::kFixedScored - 20);
  EXPECT_LE(wrong, carrier::kWrong + 2);
  EXPECT_LE(100.0 * wrong, 1.0 * scored);  // issue 48: <= 1 % wrong
  EXPECT_LT(rms_on_fixed, kMargin * carrier::kRmsOnFixed_m);
  EXPECT_NEAR(fwd->epochs_compared, kForwardEpochs, 0.01 * kForwardEpochs);
  EXPECT_LT(fwd->horizontal_rms_m, kMargin * carrier::kForwardRms_m);
  EXPECT_LT(smo->horizontal_rms_m, kMargin * carrier::kSmoothedRms_m);
  EXPECT_LE(fwd->horizontal_rms_m, 0.30);  // issue 48: forward <= 0.30 m
  EXPECT_LE(smo->horizontal_rms_m, 0.05);  // issue 48: smoothed <= 0.05 m
}

// GLONASS code in the tight coupling (docs/consistency.md eq. M.2a): its per-satellite FDMA biases are correlated
// errors. tc, G+R, code only, against the receiver's fixed GGA epochs; measured 2026-12-06: forward RMS 0.845 m, mean
// error 0.42 m east, 0.56 m north (without eq. M.2a 1.307 m, 1.00 / 0.73 m; GPS alone 0.729 m). Bounds +20 %.
TEST(GalwayTrack, GlonassCodeBiasesAreCorrelatedErrors) {
  const std::string nmea = test::shared_data("gnss_ublox_m8p_walk_galway/reference_nmea/rover-20181004-1532.nmea");
  PEDNAV_REQUIRE_DATA(nmea);
  const auto r = run_galway_track("galway_track_glonass", [](io::RunConfig& c) {
    c.gnss.systems = {"G", "R"};
    c.smoother_enabled = false;
  });
  ASSERT_TRUE(r.has_value());
  io::TrajectoryReadOptions fixed;
  fixed.nmea_qualities = {4};
  auto ref = io::read_trajectory(nmea, fixed);
  ASSERT_TRUE(ref.has_value());
  eval::Trajectory t;
  for (const auto& e : r->epochs) {
    t.points.push_back({e.t, e.nav.p_eb_e, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN())});
  }
  auto ev = eval::compare(t, ref->trajectory, {});
  ASSERT_TRUE(ev.has_value());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& e : ev->errors) mean += e.d_enu;
  mean /= static_cast<double>(std::max<size_t>(1, ev->errors.size()));
  std::printf("galway_track tc G+R code only: forward RMS %.3f m over %d epochs, mean error east %.2f m, north %.2f m\n",
              ev->horizontal_rms_m, ev->epochs_compared, mean.x(), mean.y());
  EXPECT_NEAR(ev->epochs_compared, kForwardEpochs, 0.01 * kForwardEpochs);
  EXPECT_LT(ev->horizontal_rms_m, kMargin * 0.845);
  EXPECT_LT(std::abs(mean.x()), kMargin * 0.42);
  EXPECT_LT(std::abs(mean.y()), kMargin * 0.56);
}

}  // namespace
}  // namespace pednav
