// SPDX-License-Identifier: BSD-2-Clause
// Fault injection into the tightly coupled engine (issue 11, docs/robustness.md): a simulated open-sky walk with a
// base, one fault per test (receiver clock jump, pseudorange blunder, missing ephemeris, base that stops, IMU garbage
// that makes the filter diverge, non-finite samples, 10 minutes without satellites). Each run must complete without
// NaN, say what happened in the summary, and stay accurate (or recover); every input is accounted for.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/engine.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "io/scenario_config.hpp"
#include "sim/simulator.hpp"

namespace pednav {
namespace {

using ::testing::HasSubstr;
using Eigen::Vector3d;

// Open sky, one lap of a 60 m x 40 m rectangle (about 3.5 min); the long variant walks 5 laps (about 14 min).
constexpr const char* kWalkYaml = R"(
name: robust_walk
seed: 31
start: {gps_week: 2300, gps_tow_s: 400000}
origin: {lat_deg: 46.5, lon_deg: 6.6, h_m: 400}
route:
  static_start_s: 30
  static_end_s: 10
  shape: {type: rectangle, east_m: 60, north_m: 40, laps: LAPS}
gait: {speed_mps: 1.2, cycle_s: 1.1}
imu: {rate_hz: 100, spec: crista, errors: true}
gnss:
  base_offset_enu_m: [200, 100, 3]
)";

constexpr double kSpeedOfLight_mps = 299792458.0;
constexpr double kClockJump_s = 1e-3;           // issue 11: a 1 ms receiver clock jump
constexpr double kBlunder_m = 300.0;            // issue 11: a 300 m pseudorange blunder on one satellite
constexpr double kBlunderDuration_s = 60.0;
constexpr double kOutage_s = 600.0;             // issue 11: 10 minutes without satellites
// The no-fault baseline (forward TC on this walk), measured 2026-12-05: 205 epochs, RMS 0.98 m, max 8.53 m at the
// first output epoch, max 2.29 m from 1 s after the start on; bounds +20 % (another libm/compiler).
constexpr double kMaxRmsNoFault_m = 0.98 * 1.2;
constexpr double kMaxFirstEpochNoFault_m = 8.53 * 1.2;
constexpr double kMaxAfterFirstSecondNoFault_m = 2.29 * 1.2;
// Bounds of the fault cases: the figure measured on 2026-12-05 (quoted at each test) times kMargin, which covers
// compiler/platform rounding of a run whose decisions (w-tests, re-initialization epochs) sit near thresholds
// (docs/conventions.md "Test bounds"); the issue's targets (2.5 m RMS with a handled fault, 5 m from 60 s after a
// recovery) are far looser and checked as well where they apply.
constexpr double kMargin = 1.25;
constexpr double kMaxRmsWithFault_m = 2.5;      // issue 11: a handled fault costs little accuracy
constexpr double kMaxErrorAfterRecovery_m = 5.0;// issue 11: error from 60 s after a recovery / the end of an outage
constexpr double kRecoveryTime_s = 60.0;
constexpr double kMaxOutputGap_s = 1.0 + 1e-6;  // 1 Hz output
constexpr double kMaxErrorUndifferenced_m = 10.0;
constexpr double kWrongStart_m = 300.0;           // configured start position this far off (north) ...
constexpr double kConfidentSigma_m = 0.05;        // ... with this initial position sigma  // after the base stops: undifferenced code, broadcast corrections

struct Walk {
  sim::Simulation sim;
  fusion::EngineOptions options;
};

Walk make_walk(int laps) {
  std::string text = kWalkYaml;
  text.replace(text.find("LAPS"), 4, std::to_string(laps));
  auto file = io::parse_scenario(text, "robust_walk.yaml", ".");
  EXPECT_TRUE(file.has_value()) << (file ? "" : file.error().message);
  auto s = sim::simulate(file->scenario);
  EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
  Walk w{std::move(*s), {}};
  io::RunConfig c;  // the configuration `pednav simulate` writes, mode tc
  c.mode = "tc";
  c.imu.spec = file->scenario.imu.spec;
  w.options = pipeline::engine_options(c);
  w.options.base_position_e = w.sim.gnss.p_base_e;
  w.options.smoother_enabled = false;
  return w;
}

Walk& short_walk() {
  static Walk w = make_walk(1);
  return w;
}

struct Inputs {
  std::vector<ins::ImuSample> imu;
  std::vector<gnss::ObsEpoch> rover, base;
  gnss::NavData nav;
};

Inputs inputs_of(const Walk& w) { return {w.sim.imu, w.sim.gnss.rover.epochs, w.sim.gnss.base.epochs, w.sim.nav}; }

Expected<fusion::EngineResult> run(const Walk& w, const Inputs& in, const fusion::EngineOptions& o) {
  fusion::EngineInputs ei;
  ei.imu = &in.imu;
  ei.nav = &in.nav;
  ei.rover = &in.rover;
  ei.base = in.base.empty() ? nullptr : &in.base;
  fusion::EngineOptions opt = o;
  if (in.base.empty()) opt.base_position_e.reset();
  (void)w;
  return fusion::run_forward(ei, opt);
}

// Horizontal errors [m] of the forward solution against the truth (all outputs, and those from t_from on).
struct Errors {
  double rms = 0, max = 0, max_from = 0;
  long n = 0;
  double inside_3sigma = 0;  // fraction of outputs with both the north and the east error inside 3σ
};

Errors errors(const Walk& w, const fusion::EngineResult& r, GpsTime t_from) {
  const auto& nav = w.sim.truth.nav;
  const double rate = w.sim.scenario.imu.rate_hz;
  Errors e;
  double ss = 0;
  for (const auto& out : r.epochs) {
    EXPECT_TRUE(out.nav.p_eb_e.allFinite() && out.nav.v_eb_e.allFinite() && out.cov_p_n.allFinite())
        << out.t.to_string();
    const long i = std::lround((out.t - nav.front().t) * rate);
    if (i < 0 || i >= static_cast<long>(nav.size())) continue;
    const Vector3d enu = enu_from_ecef(out.nav.p_eb_e, nav[i].p_eb_e);
    const double d = enu.head<2>().norm();
    if (std::abs(enu.y()) <= 3.0 * std::sqrt(out.cov_p_n(0, 0)) && std::abs(enu.x()) <= 3.0 * std::sqrt(out.cov_p_n(1, 1)))
      e.inside_3sigma += 1.0;
    ss += d * d;
    e.max = std::max(e.max, d);
    if (out.t >= t_from) e.max_from = std::max(e.max_from, d);
    ++e.n;
  }
  e.rms = e.n ? std::sqrt(ss / static_cast<double>(e.n)) : 0.0;
  if (e.n) e.inside_3sigma /= static_cast<double>(e.n);
  return e;
}

long sum_of(const std::map<std::string, long>& m) {
  return std::accumulate(m.begin(), m.end(), 0L, [](long a, const auto& kv) { return a + kv.second; });
}

// read = used + rejected (by reason) + skipped (by reason), for IMU samples and rover measurements.
void expect_accounting(const Inputs& in, const fusion::EngineSummary& s) {
  EXPECT_EQ(static_cast<long>(in.imu.size()), s.imu_samples_used + sum_of(s.imu_rejected) + sum_of(s.imu_skipped));
  long sats = 0;
  for (const auto& e : in.rover) sats += static_cast<long>(e.sats.size());
  EXPECT_EQ(s.gnss_measurements, sats);
  EXPECT_EQ(s.gnss_measurements, sum_of(s.code_used_rejected) + sum_of(s.gnss_skipped));
}

GpsTime mid_time(const Walk& w) {
  const auto& r = w.sim.gnss.rover.epochs;
  return r[r.size() / 2].time;
}

// The satellite seen in the most rover epochs (a high one for most of the walk).
gnss::SatId busiest_sat(const Inputs& in) {
  std::map<std::pair<int, int>, int> n;
  for (const auto& e : in.rover)
    for (const auto& s : e.sats) ++n[{static_cast<int>(s.sat.system), s.sat.prn}];
  auto best = std::max_element(n.begin(), n.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  return gnss::SatId{static_cast<gnss::System>(best->first.first), best->first.second};
}

long count_of(const std::map<std::string, long>& m, const std::string& key) {
  auto it = m.find(key);
  return it == m.end() ? 0 : it->second;
}

TEST(RobustGnssFault, NoFaultBaselineIsAccurateAndAccountsForEveryInput) {
  Walk& w = short_walk();
  const Inputs in = inputs_of(w);
  auto r = run(w, in, w.options);
  ASSERT_TRUE(r) << r.error().message;
  // The max (8.53 m) is the first output epoch, 0.05 s after the IMU start (one 20 Hz step): the position there is
  // the GNSS epoch solution the filter started from (SD code of 5 satellites, one rejected; σ_N 2.65 m, σ_E 1.82 m),
  // before any filtering: −6.89 m north, −5.03 m east, 2.6 and 2.8 σ. One second later the error is 2.29 m, the
  // largest from then on; the heading fit (until 79 s) and the end of the walk show no spike (docs/robustness.md §1).
  const GpsTime t_start = w.sim.truth.nav.front().t;
  const Errors e = errors(w, *r, t_start.plus_s(1.0));
  std::printf("[ robust ] no fault: %ld epochs, horizontal RMS %.2f m, max %.2f m (first output epoch), max from 1 s "
              "on %.2f m\n", e.n, e.rms, e.max, e.max_from);
  EXPECT_EQ(e.n, 205);  // 1 Hz over the 3.4-minute walk, plus the first step
  EXPECT_LT(e.rms, kMaxRmsNoFault_m);
  EXPECT_LT(e.max, kMaxFirstEpochNoFault_m);
  EXPECT_LT(e.max_from, kMaxAfterFirstSecondNoFault_m);
  EXPECT_TRUE(r->summary.covariance_healthy) << r->summary.health_message;
  EXPECT_EQ(r->summary.reinitializations, 0);
  expect_accounting(in, r->summary);
}

// The walk's gyro clips (the Crista's 300 °/s against swing peaks of 457 °/s: 297 runs of up to 10 samples on the
// across-foot axis). The runs are reconstructed from their neighbours with a σ in the process noise (docs/ins.md §9):
// without that the lost pitch of every swing makes the forward solution worse and its σ dishonest, and estimated
// accelerometer scale factors run away with it (docs/consistency.md §3.3).
TEST(RobustImuFault, ClippedGyroRunsAreReconstructedAndTheSigmaStaysHonest) {
  Walk& w = short_walk();
  const Inputs in = inputs_of(w);
  struct Case {
    const char* name;
    bool repair, accel_scale;
  };
  std::map<std::string, Errors> got;
  double max_added_deg = 0.0;
  for (const Case c : {Case{"repair", true, false}, Case{"no repair", false, false}, Case{"repair + accel scale", true, true},
                       Case{"no repair + accel scale", false, true}}) {
    fusion::EngineOptions o = w.options;
    o.repair_saturation = c.repair;
    o.estimate_scale_factors = c.accel_scale;
    o.estimate_gyro_scale_factors = false;
    auto r = run(w, in, o);
    ASSERT_TRUE(r) << r.error().message;
    const Errors e = errors(w, *r, GpsTime{});
    std::printf("[ robust ] clipped gyro, %s: horizontal RMS %.2f m, %.1f %% inside 3 sigma; %ld runs, %ld reconstructed, "
                "largest added angle %.1f deg\n",
                c.name, e.rms, 100.0 * e.inside_3sigma, r->summary.saturated_runs, r->summary.saturated_runs_reconstructed,
                r->summary.saturation_max_added_deg);
    if (c.repair) {
      max_added_deg = r->summary.saturation_max_added_deg;
      EXPECT_GT(r->summary.saturated_runs, 250);
      EXPECT_EQ(r->summary.saturated_runs_reconstructed, r->summary.saturated_runs);
      EXPECT_GT(r->summary.saturated_samples, 2000);
    } else {
      EXPECT_EQ(r->summary.saturated_runs, 0);
    }
    got[c.name] = e;
  }
  // Measured 2026-12-05: 0.91 m / 100 % with the repair, 1.20 m / 81 % without; with accelerometer scale states
  // 0.95 m / 100 % against 4.09 m / 19.5 %; largest added angle 10.4° (297 runs).
  EXPECT_LT(got["repair"].rms, 0.91 * kMargin);
  EXPECT_GE(got["repair"].inside_3sigma, 0.97);
  EXPECT_GT(got["no repair"].rms, got["repair"].rms + 0.15);
  EXPECT_LT(got["no repair"].inside_3sigma, 0.9);
  EXPECT_LT(got["repair + accel scale"].rms, 0.95 * kMargin);
  EXPECT_GE(got["repair + accel scale"].inside_3sigma, 0.97);
  EXPECT_GT(got["no repair + accel scale"].rms, 2.0);
  EXPECT_GT(max_added_deg, 10.4 / kMargin);
  EXPECT_LT(max_added_deg, 10.4 * kMargin);
}

TEST(RobustGnssFault, ReceiverClockJumpOf1msResetsTheClock) {
  Walk& w = short_walk();
  Inputs in = inputs_of(w);
  const GpsTime t_jump = mid_time(w);
  for (auto& e : in.rover) {
    if (e.time < t_jump) continue;
    for (auto& s : e.sats) s.pseudorange_m += kSpeedOfLight_mps * kClockJump_s;  // 299.8 km on every satellite
  }
  auto r = run(w, in, w.options);
  ASSERT_TRUE(r) << r.error().message;
  const Errors e = errors(w, *r, t_jump);
  std::printf("[ robust ] 1 ms clock jump: RMS %.2f m, max after the jump %.2f m, %ld clock resets\n", e.rms, e.max_from,
              r->summary.clock_resets);
  // Measured 2026-12-05: RMS 0.97 m, max after the jump 1.33 m, 1 clock reset.
  EXPECT_GE(r->summary.clock_resets, 1);
  EXPECT_LE(r->summary.clock_resets, 2);
  EXPECT_LT(e.rms, std::min(kMaxRmsWithFault_m, 0.97 * kMargin));
  EXPECT_LT(e.max_from, 1.33 * kMargin);
  EXPECT_TRUE(r->summary.covariance_healthy) << r->summary.health_message;
  expect_accounting(in, r->summary);
}

TEST(RobustGnssFault, PseudorangeBlunderOf300mOnOneSatelliteIsRejected) {
  Walk& w = short_walk();
  Inputs in = inputs_of(w);
  const gnss::SatId bad = busiest_sat(in);
  const GpsTime t0 = mid_time(w);
  long blundered = 0;
  for (auto& e : in.rover) {
    if (e.time < t0 || e.time - t0 > kBlunderDuration_s) continue;
    for (auto& s : e.sats) {
      if (s.sat == bad && !std::isnan(s.pseudorange_m)) {
        s.pseudorange_m += kBlunder_m;
        ++blundered;
      }
    }
  }
  ASSERT_GT(blundered, 50);
  auto r = run(w, in, w.options);
  ASSERT_TRUE(r) << r.error().message;
  const Errors e = errors(w, *r, t0);
  const long faults = count_of(r->summary.code_used_rejected, "innovation_fault");
  std::printf("[ robust ] 300 m blunder on %ld epochs: %ld code rejections, RMS %.2f m, max after %.2f m\n", blundered,
              faults, e.rms, e.max_from);
  // Measured 2026-12-05: 113 code rejections (the 60 blundered measurements and ones of the clean walk, whose
  // baseline rejects some too), RMS 0.94 m, max after the blunder starts 0.94 m.
  EXPECT_GE(faults, blundered);
  EXPECT_LE(faults, static_cast<long>(113 * kMargin));
  EXPECT_LT(e.rms, std::min(kMaxRmsWithFault_m, 0.94 * kMargin));
  EXPECT_LT(e.max_from, 0.94 * kMargin);
  expect_accounting(in, r->summary);
}

// A bias below the single-epoch w-test's reach (0.6 of the satellite's minimal detectable bias) held for 60 s on one
// satellite: the persistent-fault test (window of 4 consecutive epochs, docs/fusion.md §6.2) rejects it in its first
// epochs, until the satellite's multipath state has taken the bias up (then its innovations are small again). Measured:
// 3 % of its epochs rejected by the single-epoch test, 32 % with the window.
TEST(RobustGnssFault, SmallPersistentBiasIsFoundOverConsecutiveEpochs) {
  Walk& w = short_walk();
  const Inputs clean = inputs_of(w);
  const gnss::SatId bad = busiest_sat(clean);
  const GpsTime t0 = mid_time(w);
  auto in_window = [&](GpsTime t) { return !(t < t0) && t - t0 <= kBlunderDuration_s; };
  fusion::EngineOptions o = w.options;
  o.record_gnss_rows = true;
  auto r0 = run(w, clean, o);
  ASSERT_TRUE(r0) << r0.error().message;
  std::vector<double> mdb;
  for (const auto& row : r0->gnss_rows) {
    if (!row.doppler && row.sat == bad && in_window(row.t)) mdb.push_back(row.mdb);
  }
  ASSERT_GT(mdb.size(), 50u);
  std::nth_element(mdb.begin(), mdb.begin() + static_cast<long>(mdb.size() / 2), mdb.end());
  const double bias_m = 0.6 * mdb[mdb.size() / 2];
  Inputs in = clean;
  for (auto& e : in.rover) {
    if (!in_window(e.time)) continue;
    for (auto& s : e.sats) {
      if (s.sat == bad && !std::isnan(s.pseudorange_m)) s.pseudorange_m += bias_m;
    }
  }
  auto rejected_fraction = [&](int window, long& persistent) {
    fusion::EngineOptions ow = o;
    ow.fault_window_epochs = window;
    auto r = run(w, in, ow);
    EXPECT_TRUE(r) << r.error().message;
    if (!r) return 0.0;
    long n = 0, rejected = 0;
    for (const auto& row : r->gnss_rows) {
      if (row.doppler || row.sat != bad || !in_window(row.t)) continue;
      ++n;
      rejected += row.rejected;
    }
    persistent = count_of(r->summary.code_used_rejected, "persistent_fault");
    expect_accounting(in, r->summary);
    return n > 0 ? static_cast<double>(rejected) / static_cast<double>(n) : 0.0;
  };
  long persistent_off = 0, persistent_on = 0;
  const double off = rejected_fraction(0, persistent_off);
  const double on = rejected_fraction(4, persistent_on);
  std::printf("[ robust ] %.1f m bias (0.6 MDB) on %s for 60 s: rejected %.0f %% of its epochs by the single-epoch "
              "test, %.0f %% with the 4-epoch window (%ld persistent-fault rejections)\n",
              bias_m, bad.to_string().c_str(), 100.0 * off, 100.0 * on, persistent_on);
  // Measured 2026-12-05: 3 % single-epoch, 32 % with the window, 120 persistent-fault rejections.
  EXPECT_LT(off, 0.03 * 2.0);  // a fraction of 60 epochs: one epoch is 1.7 %, so 2× rather than kMargin
  EXPECT_GT(on, 0.32 / kMargin);
  EXPECT_EQ(persistent_off, 0);
  EXPECT_GT(persistent_on, static_cast<long>(120 / kMargin));
}

TEST(RobustGnssFault, MissingEphemerisOfOneSatelliteIsCountedAndTheRestUsed) {
  Walk& w = short_walk();
  Inputs in = inputs_of(w);
  const gnss::SatId gone = busiest_sat(in);
  std::erase_if(in.nav.kepler, [&](const gnss::KeplerEphemeris& k) { return k.sat == gone; });
  auto r = run(w, in, w.options);
  ASSERT_TRUE(r) << r.error().message;
  const Errors e = errors(w, *r, GpsTime{});
  const long missing = count_of(r->summary.code_used_rejected, "no_ephemeris");
  std::printf("[ robust ] no ephemeris for one satellite: %ld measurements without, RMS %.2f m\n", missing, e.rms);
  // Measured 2026-12-05: every rover epoch (205) carries the satellite without ephemeris; RMS 0.79 m.
  EXPECT_EQ(missing, e.n);
  EXPECT_LT(e.rms, std::min(kMaxRmsWithFault_m, 0.79 * kMargin));
  expect_accounting(in, r->summary);
}

TEST(RobustGnssFault, BaseThatStopsIsReportedAndTheRunContinues) {
  Walk& w = short_walk();
  Inputs in = inputs_of(w);
  const GpsTime t_stop = mid_time(w);
  std::erase_if(in.base, [&](const gnss::ObsEpoch& e) { return e.time > t_stop; });
  auto r = run(w, in, w.options);
  ASSERT_TRUE(r) << r.error().message;
  const Errors e = errors(w, *r, t_stop);
  const auto& s = r->summary;
  std::printf("[ robust ] base stops at mid-walk: %ld rover epochs undifferenced, RMS %.2f m, max after %.2f m\n",
              s.gnss_epochs_undifferenced_no_base, e.rms, e.max_from);
  // Measured 2026-12-05: 73 rover epochs undifferenced, RMS 1.06 m, max after the stop 2.00 m.
  EXPECT_GT(s.gnss_epochs_undifferenced_no_base, 30);  // processed undifferenced (broadcast clock, Klobuchar, Saastamoinen)
  EXPECT_LT(e.max_from, std::min(kMaxErrorUndifferenced_m, 2.00 * kMargin));
  EXPECT_LT(e.rms, 1.06 * kMargin);
  EXPECT_TRUE(s.covariance_healthy) << s.health_message;
  ASSERT_FALSE(r->epochs.empty());
  EXPECT_LE(w.sim.imu.back().t - r->epochs.back().t, kMaxOutputGap_s);  // the solution goes on to the end
  for (size_t k = 1; k < r->epochs.size(); ++k) ASSERT_LE(r->epochs[k].t - r->epochs[k - 1].t, kMaxOutputGap_s);
  expect_accounting(in, r->summary);
}

TEST(RobustHealth, DivergenceFromImuGarbageIsReportedAndReinitializedFromGnss) {
  Walk& w = short_walk();
  Inputs in = inputs_of(w);
  const GpsTime t0 = mid_time(w);
  long hit = 0;
  for (auto& s : in.imu) {
    if (s.t < t0 || s.t - t0 > 2.0) continue;
    s.f_ib_b += Eigen::Vector3d(400.0, 0.0, 0.0);  // 2 s of an impossible 40 g push: > 100 m/s within 0.3 s
    ++hit;
  }
  ASSERT_GT(hit, 150);
  fusion::EngineOptions o = w.options;
  o.smoother_enabled = true;
  auto r = run(w, in, o);
  ASSERT_TRUE(r) << r.error().message;
  const auto& s = r->summary;
  const Errors e = errors(w, *r, t0.plus_s(2.0 + kRecoveryTime_s));
  std::string events;
  for (const auto& ev : s.health_events) events += ev + "\n";
  std::printf("[ robust ] IMU garbage: %d re-initializations, max error from 60 s after: %.2f m\n%s",
              s.reinitializations, e.max_from, events.c_str());
  EXPECT_FALSE(s.covariance_healthy);
  EXPECT_GE(s.reinitializations, 1);
  EXPECT_THAT(events, HasSubstr("filter diverged at"));
  EXPECT_THAT(events, HasSubstr("re-initialized at"));
  EXPECT_THAT(s.smoother_message, HasSubstr("not smoothed: the filter was re-initialized"));
  EXPECT_TRUE(r->smoothed.empty());
  // Measured 2026-12-05: 1 re-initialization, max error from 60 s after 1.39 m.
  EXPECT_LE(s.reinitializations, 2);
  EXPECT_LT(e.max_from, std::min(kMaxErrorAfterRecovery_m, 1.39 * kMargin));
  EXPECT_GT(count_of(s.imu_skipped, "filter_diverged"), 0);
  expect_accounting(in, s);
}

// Divergence with a plausible state and a healthy-looking covariance: the filter starts 300 m off with a 5 cm σ (a
// wrong configured position it trusts), so it rejects most code measurements epoch after epoch. The innovation
// watch calls that divergence and re-initializes from the GNSS epoch solution.
TEST(RobustHealth, ConfidentWrongPositionIsCaughtByImplausibleInnovationsAndReinitialized) {
  Walk& w = short_walk();
  const Inputs in = inputs_of(w);
  fusion::EngineOptions o = w.options;
  const Vector3d p0 = w.sim.truth.nav.front().p_eb_e;
  o.initial_position_e = p0 + R_e_n(geodetic_from_ecef(p0).lat, geodetic_from_ecef(p0).lon) * Vector3d(0, kWrongStart_m, 0);
  o.initial_sigma_pos_m = kConfidentSigma_m;
  auto r = run(w, in, o);
  ASSERT_TRUE(r) << r.error().message;
  const auto& s = r->summary;
  std::string events;
  for (const auto& ev : s.health_events) events += ev + "\n";
  const auto reinit = events.find("re-initialized at ");
  ASSERT_NE(reinit, std::string::npos) << events;
  // The first re-initialization time, from the event text ("re-initialized at 2024-02-11 15:06:40.000 GPST").
  CalendarTime c;
  ASSERT_EQ(std::sscanf(events.c_str() + reinit, "re-initialized at %d-%d-%d %d:%d:%lf", &c.year, &c.month, &c.day,
                        &c.hour, &c.minute, &c.second),
            6)
      << events;
  const GpsTime t_first = GpsTime::from_calendar_gpst(c);
  const Errors e = errors(w, *r, t_first.plus_s(kRecoveryTime_s));
  std::printf("[ robust ] start 300 m off with sigma 5 cm: %d re-initializations, max error from 60 s after the first: "
              "%.2f m\n%s",
              s.reinitializations, e.max_from, events.c_str());
  EXPECT_FALSE(s.covariance_healthy);
  // Measured 2026-12-05: 1 re-initialization, max error from 60 s after the first 1.05 m.
  EXPECT_THAT(events, HasSubstr("innovations implausible"));
  EXPECT_GE(s.reinitializations, 1);
  EXPECT_LE(s.reinitializations, 2);
  EXPECT_LT(e.max_from, std::min(kMaxErrorAfterRecovery_m, 1.05 * kMargin));
  expect_accounting(in, s);
}

TEST(RobustHealth, InsModeDivergenceStillFailsWithAClearMessage) {
  Walk& w = short_walk();
  Inputs in = inputs_of(w);
  const GpsTime t0 = mid_time(w);
  for (auto& s : in.imu)
    if (s.t >= t0 && s.t - t0 <= 2.0) s.f_ib_b += Eigen::Vector3d(400.0, 0.0, 0.0);
  fusion::EngineOptions o = w.options;
  o.mode = fusion::Mode::kInsOnly;
  o.initial_position_e = w.sim.truth.nav.front().p_eb_e;
  o.initial_yaw_rad = 0.0;
  auto r = run(w, in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("filter diverged at"));
}

TEST(RobustImuFault, NonFiniteSamplesGivenToTheEngineAreRejectedAndCounted) {
  Walk& w = short_walk();
  Inputs in = inputs_of(w);
  const size_t mid = in.imu.size() / 2;
  in.imu[mid].omega_ib_b.x() = std::numeric_limits<double>::quiet_NaN();
  in.imu[mid + 7].f_ib_b.z() = std::numeric_limits<double>::infinity();
  auto r = run(w, in, w.options);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(count_of(r->summary.imu_rejected, "non_finite"), 2);
  EXPECT_TRUE(r->summary.covariance_healthy) << r->summary.health_message;
  expect_accounting(in, r->summary);
}

TEST(RobustGnssFault, TenMinutesWithoutSatellitesBridgedByInsAndRecovered) {
  static Walk w = make_walk(5);
  Inputs in = inputs_of(w);
  const GpsTime t0 = in.rover.front().time.plus_s(90.0);
  const GpsTime t1 = t0.plus_s(kOutage_s);
  ASSERT_LT(t1, in.rover.back().time.plus_s(-kRecoveryTime_s - 30.0)) << "the walk is too short for the outage";
  std::erase_if(in.rover, [&](const gnss::ObsEpoch& e) { return e.time >= t0 && e.time < t1; });
  auto r = run(w, in, w.options);
  ASSERT_TRUE(r) << r.error().message;
  const Errors e = errors(w, *r, t1.plus_s(kRecoveryTime_s));
  // The largest error and the largest sigma during the outage.
  const Errors after_outage_start = errors(w, *r, t0);
  double sd_max = 0;
  for (const auto& out : r->epochs)
    if (out.t >= t0 && out.t < t1) sd_max = std::max(sd_max, std::sqrt(out.cov_p_n(0, 0) + out.cov_p_n(1, 1)));
  std::printf("[ robust ] 10 min without satellites: max error from the outage on %.1f m (horizontal sigma up to "
              "%.1f m), max from 60 s after %.2f m, %d re-initializations\n",
              after_outage_start.max_from, sd_max, e.max_from, r->summary.reinitializations);
  for (size_t k = 1; k < r->epochs.size(); ++k) ASSERT_LE(r->epochs[k].t - r->epochs[k - 1].t, kMaxOutputGap_s);
  // Measured 2026-12-05: max error from the outage on 2.3 m with a horizontal σ of up to 3.1 m, max from 60 s after
  // the outage 1.75 m, 0 re-initializations.
  EXPECT_LT(after_outage_start.max_from, 2.3 * kMargin);
  EXPECT_LT(after_outage_start.max_from, 3.0 * sd_max);  // inside the filter's own 3σ
  EXPECT_LT(e.max_from, std::min(kMaxErrorAfterRecovery_m, 1.75 * kMargin));
  EXPECT_GT(sd_max, 3.1 / kMargin);  // the filter knows it is coasting
  EXPECT_LT(sd_max, 3.1 * kMargin);
  EXPECT_EQ(r->summary.reinitializations, 0);
  expect_accounting(in, r->summary);
}

}  // namespace
}  // namespace pednav
