// SPDX-License-Identifier: BSD-2-Clause
// Tightly coupled filter on the simulated forest walk (datasets/forest_walk.yaml, seed 004's outdoor test): forward
// TC with SD code + Doppler, accuracy against the simulator's truth, fault rejection of the simulated blunders,
// automatic heading initialization. Bounds: the figures measured on 2026-12-05 (Release build) plus a stated margin
// (docs/conventions.md "Test bounds"); issue 5's targets are checked beside them.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <vector>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/engine.hpp"
#include "gnss/ephemeris.hpp"
#include "gnss/least_squares.hpp"
#include "gnss/measurement.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "io/scenario_config.hpp"
#include "sim/simulator.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav {
namespace {

// Issue 5's targets: RMS <= 2.0 m, max <= 7 m, >= 95 % < 5 m (seed 004 Table 2: 3.9 m, 14 m, 86.5 %). Measured
// 2026-12-05: RMS 1.08 m, max 2.54 m, 100 % < 5 m; bounds +20 % (another libm/compiler moves single epochs of a
// 1081-epoch run; the max more than the RMS, the same margin keeps both within a few decimetres).
constexpr double kMaxHorizontalRmsM = 2.0;
constexpr double kMaxHorizontalMaxM = 7.0;
constexpr double kMinPctBelow5M = 95.0;
constexpr double kMeasuredHorizontalRmsM = 1.08;
constexpr double kMeasuredHorizontalMaxM = 2.54;
constexpr double kMeasuredMinPctBelow5M = 99.0;  // measured 100 %: at most 1 % of the epochs may leave 5 m
constexpr double kMargin = 1.20;
constexpr double kMaxOutputGapS = 1.0 + 1e-6;      // 1 Hz output, no gaps = 100 % availability
constexpr double kBlunderMinM = 10.0;             // issue 5: blunders larger than this are the ones scored
// Detectability (Baarda): a blunder b on measurement i is found by the w-test with 80 % power when |b| = MDB_i
// (docs/fusion.md eq. 6.4). Measured on forest_walk 2026-12-06: 134 of 136 blunders above their MDB rejected (the two
// misses at 1.03 and 1.08 MDB), 23 of 105 below it; 3 false rejections in 10 798 tested code measurements (0.028 %).
constexpr double kSureDetectionMdb = 1.5;           // every blunder >= 1.5 MDB must be rejected (power ~99.8 %)
constexpr double kMinDetectedAboveMdb = 0.9;        // of the blunders >= 1 MDB (expected >= 0.8 at exactly 1 MDB)
// Measured counts with their margins: a count of a few decisions moves by one or two when another libm/compiler moves
// a borderline w, so the margin of a small count is absolute, of a large one relative (kMargin).
constexpr long kMeasuredMissedAboveMdb = 2, kMissedAboveMdbMargin = 2;   // bound: 4 of 136
constexpr long kMeasuredFalseRejections = 3, kFalseRejectionMargin = 2;  // bound: 5 of 10 798 (0.046 %)
constexpr long kMeasuredDetectedBelowMdb = 23;                           // bound: 23 / 1.2 = 19 of 105
// w-test rows of the run (code and Doppler): 160 rejected, 21 436 used (103 of them above the threshold in the epoch's
// first test, next to a blunder); bounds: rejected and first-test counts ±20 % (kMargin), used rows ±1 % (they are
// the data's rows above the mask less the rejected ones).
constexpr long kMeasuredRejectedRows = 160, kMeasuredUsedRows = 21436, kMeasuredUsedFirstWAbove = 103;
constexpr double kUsedRowsTolRel = 0.01;
constexpr double kHeadingWindowS = 60.0;          // yaw error < kMaxYawErrorDeg from 60 s of walking on
constexpr double kMaxYawErrorDeg = 5.0;
// Seed 24 with the defaults, measured 2026-12-05: horizontal RMS 0.91 m (8.2 m with the old heading-fit stop rule),
// worst yaw error from 60 s to 180 s of walking 1.59°; bounds +20 % (kMargin).
constexpr double kSeed24HorizontalRmsM = 0.91;
constexpr double kSeed24WorstYawDeg = 1.59;
// forest_walk (seed 2), measured 2026-12-05: yaw error 0.99° 60 s after the walk start, worst 2.38° until the end;
// the initial yaw from the heading fit 2.87° off the truth's (measured 2026-12-06; the fit's σ 1.2°).
constexpr double kYawErrorAt60sDeg = 0.99;
constexpr double kInitialYawErrorDeg = 2.87;
constexpr double kWorstYawErrorDeg = 2.38;
// Mean along-track error while walking, seed 2 (measured 2026-12-05: stride-average Doppler model −0.048 m,
// foot-velocity model −0.351 m; earlier figures: without the scale-factor errors-in-variables compensation −0.24 / −0.54 m,
// with error-free IMU data −0.07 / −0.26 m; docs/fusion.md §13, docs/consistency.md §3.7). The default's mean is
// near zero, so its bound takes an absolute margin, 0.05 m (more than 2× the figure: a relative margin of a
// near-zero mean would be round-off); the foot model's lag must show: −20 % of its figure.
constexpr double kMinMeanAlongTrackM = -0.048 - 0.05;
constexpr double kMaxMeanAlongTrackFootModelM = -0.351 / 1.20;
constexpr double kElevationMaskRad = 10.0 * kDegToRad;  // the run configuration's mask (simulate writes 10 deg)

struct TcRun {
  sim::Simulation sim;
  fusion::EngineResult result;
  double wall_s = 0;
};

TcRun* g_run = nullptr;

class ForestWalkTc : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto file = io::load_scenario("datasets/forest_walk.yaml");
    ASSERT_TRUE(file.has_value()) << file.error().message;
    auto s = sim::simulate(file->scenario);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    g_run = new TcRun{std::move(*s), {}, 0.0};
    // The configuration `pednav simulate` writes, with mode tc: defaults of io::RunConfig.
    fusion::EngineOptions o = test::tc_default_options(*file, g_run->sim);
    o.record_gnss_rows = true;  // per-measurement w-test records for the fault-rejection test
    const fusion::EngineInputs in = test::engine_inputs(g_run->sim);
    const auto t0 = std::chrono::steady_clock::now();
    auto r = fusion::run_forward(in, o);
    g_run->wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(r.has_value()) << r.error().message;
    g_run->result = std::move(*r);
    std::printf("[ forest ] run_forward: %.1f s wall, %zu output epochs; %s\n", g_run->wall_s,
                g_run->result.epochs.size(), g_run->result.summary.initialization.c_str());
  }
  static void TearDownTestSuite() {
    delete g_run;
    g_run = nullptr;
  }

  // Truth foot state at a time on the IMU grid.
  static const ins::NavState* truth_at(GpsTime t) {
    const auto& nav = g_run->sim.truth.nav;
    const double rate = g_run->sim.scenario.imu.rate_hz;
    const long i = std::lround((t - nav.front().t) * rate);
    if (i < 0 || i >= static_cast<long>(nav.size()) || std::abs(nav[i].t - t) > 1e-6) return nullptr;
    return &nav[i];
  }

  static double yaw_of(const ins::NavState& x) {
    const Geodetic llh = geodetic_from_ecef(x.p_eb_e);
    return euler_from_R_n_b(R_e_n(llh.lat, llh.lon).transpose() * x.R_e_b()).z();
  }
};

TEST_F(ForestWalkTc, HorizontalAccuracyAndAvailability) {
  const auto& epochs = g_run->result.epochs;
  ASSERT_FALSE(epochs.empty());
  EXPECT_TRUE(g_run->result.summary.covariance_healthy) << g_run->result.summary.health_message;
  // 100 % availability: a finite solution every second from the start of the IMU log to its end.
  const GpsTime imu0 = g_run->sim.imu.front().t, imu1 = g_run->sim.imu.back().t;
  EXPECT_LE(epochs.front().t - imu0, kMaxOutputGapS);
  EXPECT_LE(imu1 - epochs.back().t, kMaxOutputGapS);
  double ss = 0, mx = 0;
  long below5 = 0, n = 0;
  for (size_t k = 0; k < epochs.size(); ++k) {
    if (k > 0) {
      EXPECT_LE(epochs[k].t - epochs[k - 1].t, kMaxOutputGapS) << epochs[k].t.to_string();
    }
    ASSERT_TRUE(epochs[k].nav.p_eb_e.allFinite()) << epochs[k].t.to_string();
    const ins::NavState* tr = truth_at(epochs[k].t);
    ASSERT_NE(tr, nullptr) << "no truth at " << epochs[k].t.to_string();
    const double e = enu_from_ecef(epochs[k].nav.p_eb_e, tr->p_eb_e).head<2>().norm();
    ss += e * e;
    mx = std::max(mx, e);
    below5 += e < 5.0;
    ++n;
  }
  const double rms = std::sqrt(ss / static_cast<double>(n));
  const double pct5 = 100.0 * static_cast<double>(below5) / static_cast<double>(n);
  std::printf("[ forest ] forward TC vs truth (IMU position, %ld epochs at 1 Hz): horizontal RMS %.2f m, max %.2f m, "
              "%.1f %% < 5 m\n",
              n, rms, mx, pct5);
  EXPECT_LT(rms, kMaxHorizontalRmsM);
  EXPECT_LT(mx, kMaxHorizontalMaxM);
  EXPECT_GT(pct5, kMinPctBelow5M);
  EXPECT_LT(rms, kMargin * kMeasuredHorizontalRmsM);
  EXPECT_LT(mx, kMargin * kMeasuredHorizontalMaxM);
  EXPECT_GT(pct5, kMeasuredMinPctBelow5M);
  EXPECT_EQ(n, 1081);  // 1 Hz over the whole IMU log (availability is checked above epoch by epoch)
}

// Vertical error and σ_U of the forward solution: mean up error [m] and the fraction of epochs with |e_U| <= 3σ_U.
struct Vertical {
  double mean_up_m = 0, inside_3sigma = 0;
};
Vertical vertical_of(const fusion::EngineResult& r, const std::function<const ins::NavState*(GpsTime)>& truth_at) {
  Vertical v;
  long n = 0;
  for (const auto& e : r.epochs) {
    const ins::NavState* tr = truth_at(e.t);
    if (!tr) continue;
    const double up = enu_from_ecef(e.nav.p_eb_e, tr->p_eb_e).z();
    v.mean_up_m += up;
    v.inside_3sigma += std::abs(up) <= 3.0 * std::sqrt(e.cov_p_n(2, 2));
    ++n;
  }
  if (n) {
    v.mean_up_m /= static_cast<double>(n);
    v.inside_3sigma /= static_cast<double>(n);
  }
  return v;
}

// The tc defaults estimate the scale factors and model the turn-on bias as a random constant (docs/consistency.md
// §3.2-3.4). With the earlier defaults (no scale states, Gauss-Markov bias) the same run is +1.8 m up with 15 % of
// the epochs inside 3σ_U (+1.89 m before the saturation repair). Of the remaining mean, +0.35 m is the geometry: the
// default lever arm (1.2 m) is shorter than the simulated walker's foot-to-antenna height (1.55 m).
TEST_F(ForestWalkTc, VerticalSigmaIsHonest) {
  const Vertical now = vertical_of(g_run->result, truth_at);
  auto file = io::load_scenario("datasets/forest_walk.yaml");
  ASSERT_TRUE(file.has_value()) << file.error().message;
  fusion::EngineOptions o = test::tc_default_options(*file, g_run->sim);
  EXPECT_TRUE(o.estimate_scale_factors);
  EXPECT_TRUE(o.estimate_gyro_scale_factors);
  EXPECT_TRUE(o.bias_random_walk);
  o.estimate_scale_factors = false;
  o.bias_random_walk = false;
  o.smoother_enabled = false;
  auto before = fusion::run_forward(test::engine_inputs(g_run->sim), o);
  ASSERT_TRUE(before.has_value()) << before.error().message;
  const Vertical old = vertical_of(*before, truth_at);
  std::printf("[ forest ] vertical: mean up error %+.2f m, %.1f %% inside 3 sigma_U (without the scale-factor states "
              "and the random-walk bias: %+.2f m, %.1f %%)\n",
              now.mean_up_m, 100.0 * now.inside_3sigma, old.mean_up_m, 100.0 * old.inside_3sigma);
  // Measured 2026-12-05: +0.38 m, 100 % inside 3σ_U; without the scale-factor states and the random-walk bias
  // +1.88 m, 16.8 %. Bounds: the measured figure +20 % (kMargin), or −20 % where the defect must show.
  EXPECT_LT(std::abs(now.mean_up_m), kMargin * 0.38);
  EXPECT_GE(now.inside_3sigma, 0.99);
  EXPECT_GT(old.mean_up_m, 1.88 / kMargin);
  EXPECT_LT(old.inside_3sigma, kMargin * 0.168);
}

// Mean along-track error [m] of the forward solution while walking (truth foot speed over ±2.5 s above 0.5 m/s;
// negative = behind the walker), the direction from the truth positions 2.5 s before and after.
double mean_along_track_error_m(const fusion::EngineResult& r, const std::function<const ins::NavState*(GpsTime)>& truth) {
  double sum = 0.0;
  long n = 0;
  for (const auto& ep : r.epochs) {
    const ins::NavState *a = truth(ep.t.plus_s(-2.5)), *b = truth(ep.t.plus_s(2.5)), *c = truth(ep.t);
    if (!a || !b || !c) continue;
    const Eigen::Vector2d d = enu_from_ecef(b->p_eb_e, c->p_eb_e).head<2>() - enu_from_ecef(a->p_eb_e, c->p_eb_e).head<2>();
    if (d.norm() < 0.5 * 5.0) continue;
    sum += enu_from_ecef(ep.nav.p_eb_e, c->p_eb_e).head<2>().dot(d.normalized());
    ++n;
  }
  return n > 0 ? sum / static_cast<double>(n) : std::nan("");
}

// The antenna rides on the walker's body, which moves at the walking speed while the IMU foot stands still or swings
// at twice that speed. Predicting its Doppler from the foot's own velocity makes the filter lag the walker along-track
// (docs/fusion.md §13); the stride-average model (the default) does not.
TEST_F(ForestWalkTc, BodyAntennaDopplerDoesNotMakeTheFootLagAlongTrack) {
  auto file = io::load_scenario("datasets/forest_walk.yaml");
  ASSERT_TRUE(file.has_value()) << file.error().message;
  fusion::EngineOptions o = test::tc_default_options(*file, g_run->sim);
  EXPECT_EQ(o.antenna_velocity_model, fusion::AntennaVelocityModel::kStrideAverage);
  o.antenna_velocity_model = fusion::AntennaVelocityModel::kFoot;
  o.smoother_enabled = false;
  auto foot = fusion::run_forward(test::engine_inputs(g_run->sim), o);
  ASSERT_TRUE(foot.has_value()) << foot.error().message;
  const double now = mean_along_track_error_m(g_run->result, truth_at);
  const double old = mean_along_track_error_m(*foot, truth_at);
  std::printf("[ forest ] mean along-track error while walking: %+.3f m (foot-velocity Doppler model: %+.3f m)\n", now,
              old);
  EXPECT_GT(now, kMinMeanAlongTrackM);
  EXPECT_LT(old, kMaxMeanAlongTrackFootModelM);
}

// residuals.csv's w_final: the w of the last test each row took part in. Used rows passed the final test
// (w_final² ≤ the threshold), rejected rows failed theirs; the first-test w of used rows can exceed the threshold
// when another row of the epoch is a blunder (Baarda's w-statistics are correlated) — seen at forest_walk's walk
// start (w up to 14.8 on rows with 0.2 m innovations next to a −56 m blunder).
TEST_F(ForestWalkTc, FinalWOfUsedRowsPassesTheTestAndOfRejectedRowsFailsIt) {
  const double threshold = gnss::chi_square_quantile(0.999, 1);
  long used = 0, rejected = 0, used_first_w_above = 0;
  for (const auto& r : g_run->result.gnss_rows) {
    if (r.rejected) {
      ++rejected;
      EXPECT_GT(r.w_final * r.w_final, threshold) << r.sat.to_string() << " at " << r.t.to_string();
    } else {
      ++used;
      EXPECT_LE(r.w_final * r.w_final, threshold * (1.0 + 1e-9)) << r.sat.to_string() << " at " << r.t.to_string();
      used_first_w_above += r.w * r.w > threshold ? 1 : 0;
    }
  }
  std::printf("[ forest ] w-test rows: %ld used (%ld of them above the threshold in the epoch's first test), %ld "
              "rejected\n", used, used_first_w_above, rejected);
  ASSERT_GT(rejected, 50);
  EXPECT_GT(used_first_w_above, 0) << "the first-test w and w_final must differ somewhere for this test to mean much";
  EXPECT_GT(rejected, kMeasuredRejectedRows / kMargin);
  EXPECT_LT(rejected, kMeasuredRejectedRows * kMargin);
  EXPECT_NEAR(static_cast<double>(used), kMeasuredUsedRows, kUsedRowsTolRel * kMeasuredUsedRows);
  EXPECT_LT(used_first_w_above, kMeasuredUsedFirstWAbove * kMargin);
}

TEST_F(ForestWalkTc, EveryDetectableBlunderIsRejected) {
  // Every simulated rover blunder > 10 m is matched to the filter's w-test record of that satellite and epoch
  // (EngineResult::gnss_rows). Issue 5 asks for every blunder > 10 m; under foliage the SD code σ is 4-17 m, so a
  // 10-30 m blunder is often statistically invisible. The test therefore requires what a test can guarantee: every
  // blunder above 1.5 MDB rejected, >= 90 % above 1 MDB, and few false rejections.
  const sim::Simulation& s = g_run->sim;
  std::map<std::pair<int64_t, std::string>, const fusion::GnssRowRecord*> code;
  long tested = 0, rejected_total = 0;
  for (const auto& r : g_run->result.gnss_rows) {
    if (r.doppler) continue;
    code[{r.t.ns(), r.sat.to_string()}] = &r;
    ++tested;
    rejected_total += r.rejected ? 1 : 0;
  }
  ASSERT_GT(tested, 1000);
  std::set<std::pair<int64_t, std::string>> blundered;  // any size
  long small = 0, untested = 0, sure = 0, sure_det = 0, above = 0, above_det = 0, below = 0, below_det = 0;
  for (const auto& b : s.gnss.blunders) {
    const std::pair<int64_t, std::string> key{b.t.ns(), b.sat.to_string()};
    blundered.insert(key);
    if (std::abs(b.error_m) <= kBlunderMinM) {
      ++small;
      continue;
    }
    auto it = code.find(key);
    if (it == code.end()) {  // below the mask, not seen by the base, or epoch not processed
      ++untested;
      continue;
    }
    const fusion::GnssRowRecord& r = *it->second;
    const double ratio = std::abs(b.error_m) / r.mdb;
    if (ratio >= kSureDetectionMdb) {
      ++sure;
      sure_det += r.rejected;
      EXPECT_TRUE(r.rejected) << b.sat.to_string() << " at " << b.t.to_string() << ": blunder " << b.error_m
                              << " m = " << ratio << " MDB, w = " << r.w;
    }
    if (ratio >= 1.0) {
      ++above;
      above_det += r.rejected;
    } else {
      ++below;
      below_det += r.rejected;
    }
  }
  long false_rej = 0;
  for (const auto& [key, r] : code) false_rej += (r->rejected && !blundered.count(key)) ? 1 : 0;
  const auto& sum = g_run->result.summary.code_used_rejected;
  const long fault = sum.count("innovation_fault") ? sum.at("innovation_fault") : 0;
  std::printf("[ forest ] blunders: %zu simulated rover sat-epochs (%d events), %ld <= 10 m, %ld > 10 m not tested "
              "(mask/base); > 10 m and >= %.1f MDB: %ld/%ld rejected; >= 1 MDB: %ld/%ld; < 1 MDB: %ld/%ld; false "
              "rejections %ld of %ld tested code measurements (%.2f %%)\n",
              s.gnss.blunders.size(), s.gnss.blunder_events, small, untested, kSureDetectionMdb, sure_det, sure,
              above_det, above, below_det, below, false_rej, tested, 100.0 * false_rej / tested);
  EXPECT_GT(above, 50) << "the scenario must exercise the fault rejection";
  EXPECT_EQ(small + untested + above + below, static_cast<long>(s.gnss.blunders.size()));
  EXPECT_GE(static_cast<double>(above_det) / static_cast<double>(std::max(1L, above)), kMinDetectedAboveMdb);
  EXPECT_LE(above - above_det, kMeasuredMissedAboveMdb + kMissedAboveMdbMargin);
  EXPECT_GT(below_det, kMeasuredDetectedBelowMdb / kMargin);
  EXPECT_LE(false_rej, kMeasuredFalseRejections + kFalseRejectionMargin);
  EXPECT_EQ(rejected_total, fault) << "the per-measurement records must add up to the summary count";
  long per_epoch = 0;
  for (const auto& e : g_run->result.epochs) per_epoch += e.n_sats_rejected;
  EXPECT_EQ(per_epoch, fault) << "per-epoch rejections must add up to the summary count";
}

// The persistent-fault test (docs/fusion.md §6.2, `fault_rejection.window_epochs`, off by default): the simulated
// blunders last 2-10 s, so most of those below their single-epoch MDB show over consecutive epochs. Measured with a
// 4-epoch window (2026-12-06): 207 of the 241 tested blunders > 10 m rejected (157 without), 136 persistent-fault
// rejections, 15 false rejections in 10 798 (3 without), horizontal RMS 1.03 m (1.08 m without). Bounds: the missed
// blunders (34 with the window, 84 without), the gain (50) and the persistent-fault count at the measured figure ±20 %
// (kMargin); the false rejections at 15 + 3 (20 %) and 3 + 2 (kFalseRejectionMargin).
TEST_F(ForestWalkTc, PersistentFaultWindowFindsMoreOfTheBlunders) {
  auto file = io::load_scenario("datasets/forest_walk.yaml");
  ASSERT_TRUE(file.has_value()) << file.error().message;
  fusion::EngineOptions o = test::tc_default_options(*file, g_run->sim);
  o.record_gnss_rows = true;
  auto score = [&](const fusion::EngineResult& r, long& detected, long& scored, long& false_rej, long& tested) {
    std::map<std::pair<int64_t, std::string>, double> blunder;
    for (const auto& b : g_run->sim.gnss.blunders) blunder[{b.t.ns(), b.sat.to_string()}] = b.error_m;
    detected = scored = false_rej = tested = 0;
    for (const auto& row : r.gnss_rows) {
      if (row.doppler) continue;
      ++tested;
      const auto it = blunder.find({row.t.ns(), row.sat.to_string()});
      if (it == blunder.end()) {
        false_rej += row.rejected;
      } else if (std::abs(it->second) > kBlunderMinM) {
        ++scored;
        detected += row.rejected;
      }
    }
  };
  long det0 = 0, n0 = 0, false0 = 0, tested0 = 0;
  score(g_run->result, det0, n0, false0, tested0);
  o.fault_window_epochs = 4;
  auto r = fusion::run_forward(test::engine_inputs(g_run->sim), o);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  long det = 0, n = 0, false_rej = 0, tested = 0;
  score(*r, det, n, false_rej, tested);
  const long persistent = r->summary.code_used_rejected.count("persistent_fault")
                              ? r->summary.code_used_rejected.at("persistent_fault") : 0;
  std::printf("[ forest ] blunders > 10 m rejected: %ld/%ld single-epoch test, %ld/%ld with the 4-epoch window (%ld "
              "persistent-fault rejections); false rejections %ld -> %ld of %ld\n",
              det0, n0, det, n, persistent, false0, false_rej, tested);
  EXPECT_EQ(g_run->result.summary.code_used_rejected.at("persistent_fault"), 0) << "off by default";
  EXPECT_GE(static_cast<double>(det), 0.8 * static_cast<double>(n));
  constexpr long kMissedWithWindow = 34, kMissedSingleEpoch = 84, kGain = 50, kPersistentRejections = 136;
  constexpr long kFalseWithWindow = 15, kFalseWithWindowMargin = 3;
  EXPECT_EQ(n, n0) << "both runs test the same blunders";
  EXPECT_LT(n - det, kMissedWithWindow * kMargin);
  EXPECT_LT(n0 - det0, kMissedSingleEpoch * kMargin);
  EXPECT_GT(det - det0, kGain / kMargin);
  EXPECT_GT(persistent, kPersistentRejections / kMargin);
  EXPECT_LE(false_rej, kFalseWithWindow + kFalseWithWindowMargin);
  EXPECT_LE(false0, kMeasuredFalseRejections + kFalseRejectionMargin);
}

TEST_F(ForestWalkTc, HeadingFromMotionConvergesWithin60sOfWalking) {
  const sim::Simulation& s = g_run->sim;
  ASSERT_FALSE(s.plan.strides.empty());
  const GpsTime walk0 = s.scenario.start.plus_s(s.plan.strides.front().t_lift_s);
  EXPECT_NE(g_run->result.summary.initialization.find("heading from motion"), std::string::npos)
      << g_run->result.summary.initialization;
  double worst_deg = 0, first_after_deg = -1;
  GpsTime worst_t;
  for (const auto& e : g_run->result.epochs) {
    if (e.t - walk0 < kHeadingWindowS) continue;
    const ins::NavState* tr = truth_at(e.t);
    ASSERT_NE(tr, nullptr);
    const double err = std::abs(wrap_pi(yaw_of(e.nav) - yaw_of(*tr))) * kRadToDeg;
    if (first_after_deg < 0) first_after_deg = err;
    if (err > worst_deg) {
      worst_deg = err;
      worst_t = e.t;
    }
  }
  std::printf("[ forest ] heading: initial yaw %.1f deg (%s); yaw error %.2f deg at walk start + 60 s, worst %.2f deg "
              "(at walk start + %.0f s) until the end\n",
              g_run->result.summary.initial_yaw_deg, "from motion", first_after_deg, worst_deg, worst_t - walk0);
  EXPECT_LT(worst_deg, kMaxYawErrorDeg);
  EXPECT_LT(worst_deg, kMargin * kWorstYawErrorDeg);
  // 0.99° measured: +30 % (a single epoch's yaw error, more variable than the worst over the run).
  EXPECT_LT(first_after_deg, 1.30 * kYawErrorAt60sDeg);
  // The yaw the filter started with (from the heading fit) against the truth's during the static start, +30 % as above.
  // The time of the worst epoch (232 s after the walk start) is printed for the reader, not a figure to bound.
  const double initial_error_deg =
      std::abs(wrap_pi(g_run->result.summary.initial_yaw_deg * kDegToRad - yaw_of(s.truth.nav.front()))) * kRadToDeg;
  std::printf("[ forest ] initial yaw error %.2f deg\n", initial_error_deg);
  EXPECT_LT(initial_error_deg, 1.30 * kInitialYawErrorDeg);
}

// Regression (found 2026-12-01): with the old stop rule ("the GNSS epoch solutions have moved 30 m from the first"),
// forest_walk seed 24 ended the heading fit at 34 s into its 120 s static start, where a GNSS solution had jumped by
// noise and blunders: the fit had nothing to rotate (yaw σ clamped at 30°), the filter started 139° off, collapsed
// its yaw σ to 2° at a 71° error within 6 s of walking and diverged (forward RMS 8.2 m, one re-initialization).
// The span now ends when the INS/ZUPT track itself has walked the distance (docs/fusion.md §8).
TEST(ForestWalkTcHeading, StaticStartGnssNoiseDoesNotEndTheHeadingFit) {
  auto file = io::load_scenario("datasets/forest_walk.yaml");
  ASSERT_TRUE(file.has_value()) << file.error().message;
  file->scenario.seed = 24;
  auto s = sim::simulate(file->scenario);
  ASSERT_TRUE(s.has_value()) << s.error().message;
  auto r = fusion::run_forward(test::engine_inputs(*s), test::tc_default_options(*file, *s));
  ASSERT_TRUE(r.has_value()) << r.error().message;
  const auto& sum = r->summary;
  std::printf("[ forest ] seed 24: %s\n", sum.initialization.c_str());
  const GpsTime walk0 = s->scenario.start.plus_s(s->plan.strides.front().t_lift_s);
  ASSERT_TRUE(sum.heading_init_end.has_value());
  EXPECT_GT(*sum.heading_init_end - walk0, 20.0) << "the heading span must contain walking";
  EXPECT_EQ(sum.reinitializations, 0) << sum.health_message;
  const auto& nav = s->truth.nav;
  const double rate = s->scenario.imu.rate_hz;
  double worst_yaw_deg = 0.0, ss = 0.0;
  for (const auto& e : r->epochs) {
    const long i = std::lround((e.t - nav.front().t) * rate);
    ASSERT_TRUE(i >= 0 && i < static_cast<long>(nav.size()));
    const Geodetic llh = geodetic_from_ecef(e.nav.p_eb_e);
    const Eigen::Matrix3d R_n_e = R_e_n(llh.lat, llh.lon).transpose();
    const double yaw = euler_from_R_n_b(R_n_e * e.nav.R_e_b()).z(), yaw_true = euler_from_R_n_b(R_n_e * nav[i].R_e_b()).z();
    // The initialization's part: from 60 s to 180 s of walking (later yaw errors are the filter's, docs/results.md).
    if (e.t - walk0 >= kHeadingWindowS && e.t - walk0 <= 3.0 * kHeadingWindowS) {
      worst_yaw_deg = std::max(worst_yaw_deg, std::abs(wrap_pi(yaw - yaw_true)) * kRadToDeg);
    }
    ss += enu_from_ecef(e.nav.p_eb_e, nav[i].p_eb_e).head<2>().squaredNorm();
  }
  const double rms = std::sqrt(ss / static_cast<double>(r->epochs.size()));
  std::printf("[ forest ] seed 24: worst yaw error from 60 s to 180 s of walking %.2f deg, horizontal RMS %.2f m\n",
              worst_yaw_deg, rms);
  EXPECT_LT(worst_yaw_deg, kMaxYawErrorDeg);
  EXPECT_LT(worst_yaw_deg, kMargin * kSeed24WorstYawDeg);
  EXPECT_LT(rms, kMargin * kSeed24HorizontalRmsM);
}

// Bad input (docs/fusion.md §8): a walk that never gets 10 m from its start gives no heading from motion; the
// message says how far the INS/ZUPT track went and what to configure.
TEST(ForestWalkTcHeading, WalkShorterThan10mIsAClearError) {
  const char* yaml = R"(
name: short_walk
seed: 3
start: {gps_week: 2300, gps_tow_s: 300000}
origin: {lat_deg: 51.08, lon_deg: -114.13, h_m: 1050}
route:
  static_start_s: 20
  static_end_s: 10
  waypoints:
    - {e_m: 0, n_m: 0}
    - {e_m: 6, n_m: 0}
imu: {rate_hz: 100, spec: crista, errors: false}
gnss: {base_offset_enu_m: [50, 20, 0]}
)";
  auto file = io::parse_scenario(yaml, "short_walk.yaml", ".");
  ASSERT_TRUE(file.has_value()) << file.error().message;
  auto s = sim::simulate(file->scenario);
  ASSERT_TRUE(s.has_value()) << s.error().message;
  auto r = fusion::run_forward(test::engine_inputs(*s), test::tc_default_options(*file, *s));
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().message.find("cannot find the initial heading from motion: the INS/ZUPT track goes"),
            std::string::npos)
      << r.error().message;
  EXPECT_NE(r.error().message.find("set initial.yaw_deg"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace pednav
