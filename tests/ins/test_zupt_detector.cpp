// SPDX-License-Identifier: BSD-2-Clause
// Tests of ins/zupt_detector.*: every detector on a synthetic still / moving log, option problems, and the HMM
// detector end to end (seed 002 initial model trained on the log itself) on a synthetic gait.
#include "ins/zupt_detector.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>

namespace pednav::ins {
namespace {

using ::testing::HasSubstr;

constexpr double kRate_hz = 200.0;
constexpr double kPi = 3.14159265358979323846;

// 1 s still, 1 s rotating and shaking, 1 s still (200 Hz).
std::vector<ImuSample> still_moving_still() {
  std::vector<ImuSample> s;
  for (int k = 0; k < 600; ++k) {
    ImuSample x;
    const double t = k / kRate_hz;
    x.t = GpsTime::from_week_tow(0, t);
    x.f_ib_b = Eigen::Vector3d(0, 0, -9.80665);
    if (k >= 200 && k < 400) {
      x.omega_ib_b = Eigen::Vector3d(0.5, 2.5 + std::sin(2 * kPi * 2 * t), 0.2);  // |ω| > 1.5 rad/s
      x.f_ib_b += Eigen::Vector3d(4.0 * std::sin(2 * kPi * 3 * t), 0, 6.0 * std::cos(2 * kPi * 2 * t));
    }
    s.push_back(x);
  }
  return s;
}

class EveryDetector : public ::testing::TestWithParam<const char*> {};

TEST_P(EveryDetector, StillIsStanceMovingIsNot) {
  const auto s = still_moving_still();
  ZuptDetectorOptions o;
  o.detector = GetParam();
  ASSERT_TRUE(o.problems().empty());
  const auto d = detect_stance(s, o);
  ASSERT_EQ(d.size(), s.size());
  // Away from the transitions (window and smoothing edges: 0.1 s).
  for (int k = 20; k < 180; ++k) EXPECT_TRUE(d[k].stance) << GetParam() << " sample " << k;
  int moving_stance = 0;
  for (int k = 220; k < 380; ++k) moving_stance += d[k].stance;
  if (std::string(GetParam()) == "mag") {
    // MAG only sees |f|: it can be fooled where |f| passes through g while moving. On this motion it is not
    // (measured 2026-12-05: 0 of 160 moving samples); 5 samples (25 ms) of slack for a sample at the threshold.
    EXPECT_LE(moving_stance, 5);
  } else {
    EXPECT_EQ(moving_stance, 0) << GetParam();
  }
  for (int k = 420; k < 580; ++k) EXPECT_TRUE(d[k].stance) << GetParam() << " sample " << k;
}

INSTANTIATE_TEST_SUITE_P(ZuptDetector, EveryDetector, ::testing::Values("shoe", "mv", "are", "mag"));

TEST(ZuptDetector, ProblemsAreReported) {
  ZuptDetectorOptions o;
  o.detector = "nope";
  o.are_threshold = 0;
  auto p = o.problems();
  ASSERT_GE(p.size(), 2u);
  EXPECT_THAT(p[0], HasSubstr("is not mv, shoe, are, mag, hmm or labels"));
  EXPECT_THAT(p[1], HasSubstr("zupt.are_threshold must be > 0"));
  o = {};
  o.detector = "hmm";
  o.hmm_decoder = "beam";
  o.hmm_observations.axis = 5;
  p = o.problems();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_THAT(p[0], HasSubstr("zupt.hmm gyro axis must be x, y or z"));
  EXPECT_THAT(p[1], HasSubstr("hmm_decoder 'beam'"));
}

// Synthetic gait about y (seed 002 Fig. 2e shape): stance 0.45 s at rest, push-off -6, swing +7, heel strike
// -3 rad/s (half sines of 0.15, 0.35, 0.1 s), 12 cycles; gait rate noise 0.03 rad/s (fixed seed).
struct Gait {
  std::vector<ImuSample> samples;
  std::vector<bool> stance;
  int stances = 0;
};

Gait synthetic_walk(int cycles) {
  struct Phase {
    double dur_s, amp_radps;
  };
  const Phase phases[] = {{0.45, 0.0}, {0.15, -6.0}, {0.35, 7.0}, {0.1, -3.0}};
  Gait g;
  double t = 0.0;
  unsigned lcg = 12345;
  auto noise = [&] {
    lcg = lcg * 1103515245u + 12345u;
    return 0.03 * (static_cast<double>((lcg >> 8) & 0xffff) / 65535.0 - 0.5);
  };
  for (int c = 0; c <= cycles; ++c) {
    for (int p = 0; p < 4; ++p) {
      if (c == cycles && p > 0) break;
      if (p == 0) ++g.stances;
      const int n = static_cast<int>(std::lround(phases[p].dur_s * kRate_hz));
      for (int k = 0; k < n; ++k) {
        ImuSample x;
        x.t = GpsTime::from_week_tow(0, t);
        x.omega_ib_b.y() = phases[p].amp_radps * std::sin(kPi * (k + 0.5) / n) + noise();
        x.f_ib_b = Eigen::Vector3d(0, 0, -9.80665);
        g.samples.push_back(x);
        g.stance.push_back(p == 0);
        t += 1.0 / kRate_hz;
      }
    }
  }
  return g;
}

// Detector `labels` takes the stance from the given per-sample labels, whatever the motion says: here the labels
// contradict the still/moving log, and the decisions follow the labels; without labels every sample is swing.
TEST(ZuptDetector, LabelsDetectorFollowsTheLabelsNotTheMotion) {
  const auto s = still_moving_still();
  ZuptDetectorOptions o;
  o.detector = "labels";
  ASSERT_TRUE(o.problems().empty());
  std::vector<uint8_t> labels(s.size(), 0);
  for (size_t k = 250; k < 350; ++k) labels[k] = 1;  // "stance" in the middle of the moving second
  const auto d = detect_stance(s, o, &labels);
  ASSERT_EQ(d.size(), s.size());
  for (size_t k = 0; k < s.size(); ++k) {
    EXPECT_EQ(d[k].stance, labels[k] != 0) << k;
    EXPECT_EQ(d[k].statistic, labels[k] != 0 ? 1.0 : 0.0) << k;
  }
  for (const auto& x : detect_stance(s, o)) EXPECT_FALSE(x.stance);
}

TEST(ZuptDetector, HmmFindsEveryStanceOfASyntheticWalk) {
  const Gait g = synthetic_walk(12);
  ZuptDetectorOptions o;
  o.detector = "hmm";
  const HmmDetection h = detect_gait_hmm(g.samples, o);
  ASSERT_EQ(h.decisions.size(), g.samples.size());
  int runs = 0, tp = 0, fp = 0, fn = 0;
  for (std::size_t k = 0; k < g.samples.size(); ++k) {
    const bool s = h.decisions[k].stance;
    runs += s && (k == 0 || !h.decisions[k - 1].stance);
    tp += s && g.stance[k];
    fp += s && !g.stance[k];
    fn += !s && g.stance[k];
  }
  EXPECT_EQ(runs, g.stances);
  // Stance = the smoothed rate within the two zero grades (|rate| < 1.05 rad/s) around a D observation: it
  // takes in < 0.02 s of each neighbouring half sine's flank (fp) and loses the smoothing edge (fn).
  // Measured 2026-12-05: 1170 true, 36 false stance samples (3 per stance), 0 missed: precision 0.970, recall 1.
  constexpr double kMinRecall = 0.99, kMinPrecision = 0.95;
  EXPECT_GT(tp, kMinPrecision * (tp + fp));
  EXPECT_GT(tp, kMinRecall * (tp + fn));
  // Trained on the log: cyclic A -> B -> C -> D -> A dominates every row.
  EXPECT_GT(h.training.log_likelihood.back(), h.training.log_likelihood.front());
  for (int i = 0; i < kHmmStates; ++i) EXPECT_GT(h.model.A(i, (i + 1) % kHmmStates), 0.9) << "row " << i << "\n" << h.model.A;
  // The forward (online) decoder gives the same stance count here.
  o.hmm_decoder = "forward";
  const auto d = detect_stance(g.samples, o);
  int runs_f = 0;
  for (std::size_t k = 0; k < d.size(); ++k) runs_f += d[k].stance && (k == 0 || !d[k - 1].stance);
  EXPECT_EQ(runs_f, g.stances);
}


// Gait whose stance rolls (heel roll +0.7 rad/s for 0.1 s, flat foot at `flat_radps` for 0.25 s, toe roll
// -0.5 rad/s for 0.1 s, both rolls on top of `flat_radps`) before push-off -6, swing +7, heel strike -3 rad/s; `stance` = the flat-foot samples.
// Outside the flat foot the specific force also vibrates (8 m/s^2 at 40 Hz, SHOE T about 130), so the SHOE statistic is not small
// where the rate crosses zero between phases.
Gait rolling_walk(int cycles, double flat_radps) {
  struct Phase {
    double dur_s, amp_radps;
    bool flat, roll;
  };
  const Phase phases[] = {{0.1, 0.7, false, true},    {0.25, 0.0, true, false},  {0.1, -0.5, false, true},
                          {0.15, -6.0, false, false}, {0.35, 7.0, false, false}, {0.1, -3.0, false, false}};
  Gait g;
  double t = 0.0;
  unsigned lcg = 777;
  auto noise = [&] {
    lcg = lcg * 1103515245u + 12345u;
    return 0.03 * (static_cast<double>((lcg >> 8) & 0xffff) / 65535.0 - 0.5);
  };
  for (int c = 0; c < cycles; ++c) {
    ++g.stances;
    for (const Phase& p : phases) {
      const int n = static_cast<int>(std::lround(p.dur_s * kRate_hz));
      for (int k = 0; k < n; ++k) {
        ImuSample x;
        x.t = GpsTime::from_week_tow(0, t);
        const double roll = p.roll ? flat_radps : 0.0;  // the rolls turn on top of the flat-foot rate
        x.omega_ib_b.y() = (p.flat ? flat_radps : roll + p.amp_radps * std::sin(kPi * (k + 0.5) / n)) + noise();
        x.f_ib_b = Eigen::Vector3d(p.flat ? 0.0 : 8.0 * std::sin(2 * kPi * 40 * t), 0, -9.80665);
        g.samples.push_back(x);
        g.stance.push_back(p.flat);
        t += 1.0 / kRate_hz;
      }
    }
  }
  return g;
}

struct StanceCount {
  int runs = 0;        // stance intervals
  int rolling = 0;     // stance samples outside the flat-foot phase
  int flat_missed = 0; // flat-foot samples not stance
};

StanceCount count(const Gait& g, const std::vector<ZuptDecision>& d) {
  StanceCount c;
  for (std::size_t k = 0; k < d.size(); ++k) {
    c.runs += d[k].stance && (k == 0 || !d[k - 1].stance);
    c.rolling += d[k].stance && !g.stance[k];
    c.flat_missed += !d[k].stance && g.stance[k];
  }
  return c;
}

TEST(ZuptDetector, HmmRefineKeepsTheQuietCoreOfEachStance) {
  const Gait g = rolling_walk(12, 0.0);
  ZuptDetectorOptions o;
  o.detector = "hmm";
  const StanceCount whole = count(g, detect_stance(g.samples, o));
  // Without refinement the decoded stance takes in the heel and toe rolls (|rate| < one grade, 1.05 rad/s).
  // Measured 2026-12-05: 582 roll samples (48 per step); bound measured / 1.3.
  constexpr int kMinRollingSamples = 582 * 10 / 13;
  EXPECT_GT(whole.rolling, kMinRollingSamples);
  o.hmm_refine_factor = 2.0;
  const StanceCount core = count(g, detect_stance(g.samples, o));
  EXPECT_EQ(core.runs, g.stances);  // still one stance per step
  // The core is the flat foot (SHOE T < γ = 10 with σω 0.1 rad/s: |rate| < 0.32 rad/s); a roll sample where the
  // 0.03 s SHOE window still averages in the flat part may join it. Measured 2026-12-05: 0 roll samples, 60 flat-foot
  // samples missed (5 per step); bounds 1 roll sample per step, the flat-foot one from its derivation below.
  constexpr int kMaxRollingPerStep = 1;
  EXPECT_LE(core.rolling, kMaxRollingPerStep * g.stances);
  // It loses at most the SHOE half window (3 samples) plus one at each end of the flat foot.
  constexpr int kMaxFlatMissedPerStep = 8;
  EXPECT_LE(core.flat_missed, kMaxFlatMissedPerStep * g.stances);
}

TEST(ZuptDetector, HmmRefineThresholdAdaptsToAFootThatNeverStops) {
  // Fast gait: the flat foot still turns at 0.6 rad/s (SHOE T about 36 > γ = 10 everywhere in stance). A fixed
  // threshold finds no stance; the refined HMM keeps one core per step around the minimum (threshold 2 T_min).
  const Gait g = rolling_walk(12, 0.6);
  ZuptDetectorOptions o;
  o.detector = "shoe";
  EXPECT_EQ(count(g, detect_stance(g.samples, o)).runs, 0);
  o.detector = "hmm";
  o.hmm_refine_factor = 2.0;
  const StanceCount c = count(g, detect_stance(g.samples, o));
  EXPECT_EQ(c.runs, g.stances);
  EXPECT_LE(c.rolling, g.stances);  // measured 2026-12-05: 0 roll samples (as for the adaptive SHOE below)
  // The gait-adaptive SHOE (threshold max(γ, 2 × the minimum of T within ±0.5 s)) finds them without the HMM.
  o.detector = "shoe";
  o.shoe_adaptive_factor = 2.0;
  o.shoe_adaptive_window_s = 1.0;
  const StanceCount a = count(g, detect_stance(g.samples, o));
  EXPECT_EQ(a.runs, g.stances);
  EXPECT_LE(a.rolling, g.stances);
}

// shoe_adaptive_min_peak_radps: the gait-adaptive threshold is raised only where a swing is near. A slow pivot (0.5
// rad/s for 2 s between two rests, SHOE T = 25 > γ = 10) is stance for the unconditioned adaptive SHOE (threshold
// 3 × 25 where no rest is within ±0.5 s: the PyShoe 2018 trial's slow motion), not with the peak condition; the fast
// gait whose flat foot never stops is decided as without it (swing peak 7 rad/s).
TEST(ZuptDetector, ShoeAdaptiveThresholdIsRaisedOnlyNearASwing) {
  std::vector<ImuSample> s;
  for (int k = 0; k < 800; ++k) {
    ImuSample x;
    x.t = GpsTime::from_week_tow(0, k / kRate_hz);
    x.f_ib_b = Eigen::Vector3d(0, 0, -9.80665);
    if (k >= 200 && k < 600) x.omega_ib_b = Eigen::Vector3d(0, 0, 0.5);
    s.push_back(x);
  }
  ZuptDetectorOptions o;
  o.detector = "shoe";
  o.shoe_adaptive_factor = 3.0;
  o.shoe_adaptive_window_s = 1.0;
  constexpr int kMidPivot = 400;  // 1 s from either rest
  EXPECT_TRUE(detect_stance(s, o)[kMidPivot].stance);
  o.shoe_adaptive_min_peak_radps = kPi;  // 180 °/s
  const auto d = detect_stance(s, o);
  EXPECT_EQ(std::count_if(d.begin() + 200, d.begin() + 600, [](const ZuptDecision& z) { return z.stance; }), 0);
  EXPECT_TRUE(d[100].stance);  // the rests stay stance
  EXPECT_TRUE(d[700].stance);
  // The fast gait: every decision the same with and without the condition (stance found where the foot never stops).
  const Gait g = rolling_walk(12, 0.6);
  const auto with_peak = detect_stance(g.samples, o);
  o.shoe_adaptive_min_peak_radps = 0.0;
  const auto without = detect_stance(g.samples, o);
  EXPECT_GE(count(g, with_peak).runs, g.stances);
  for (std::size_t k = 0; k < without.size(); ++k) ASSERT_EQ(with_peak[k].stance, without[k].stance) << k;
}

// 100 Hz samples and decisions from a gait string (D = stance, A = push-off, B = swing, C = heel strike, other
// characters: a non-stance flicker decoded as D).
void gait_from_string(const char* gait, std::vector<ImuSample>& s, std::vector<ZuptDecision>& d) {
  for (int k = 0; gait[k] != '\0'; ++k) {
    ImuSample x;
    x.t = GpsTime::from_week_tow(0, 0.01 * k);
    s.push_back(x);
    ZuptDecision z;
    const char c = gait[k];
    z.stance = c == 'D';
    z.gait_state = c == 'A' ? kPushOff : c == 'B' ? kSwing : c == 'C' ? kHeelStrike : kStance;
    d.push_back(z);
  }
}

// hmm_min_swing_s: a stance run right after a push-off is dropped, a stance broken by a flicker is not, and a
// stance after a full swing is kept (100 Hz decisions built by hand: D = stance, A = push-off, B = swing).
TEST(ZuptDetector, StanceRightAfterPushOffIsDropped) {
  const char* gait = "DDDDDDDDDDAAAAAAAAAADDDDDDDDAAAAABBBBBBBBBBBBBBBBBBBBBBBBBBBBBBBCCDDDDD.DDDDDD";
  // D 0-9, A 10-19, D 20-27, A 28-32, B 33-63, C 64-65, D 66-70, flicker 71, D 72-77
  std::vector<ImuSample> s;
  std::vector<ZuptDecision> d;
  gait_from_string(gait, s, d);
  auto stance_at = [&](int k) { return d[static_cast<std::size_t>(k)].stance; };
  drop_stances_right_after_push_off(d, s, 0.3);
  EXPECT_TRUE(stance_at(5));    // the first stance is kept
  EXPECT_FALSE(stance_at(24));  // 0.11 s after the first stance, a push-off in between: dropped
  EXPECT_TRUE(stance_at(68));   // after push-off, swing and heel strike (0.58 s): kept
  EXPECT_TRUE(stance_at(75));   // the same stance after a one-sample flicker (no push-off): kept
  // Off: nothing changes.
  std::vector<ZuptDecision> d0 = d;
  d0[24].stance = true;
  drop_stances_right_after_push_off(d0, s, 0.0);
  EXPECT_TRUE(d0[24].stance);
}

// refine_hmm_stances: a decoded stance shorter than min_stance_s that is a whole step (heel strike before it, push-off
// after it, a swing since the previous stance) is widened beyond its run to min_stance_s instead of being lost (the
// LORD #35/#38 fast steps whose stance is one observation); one that is not (a D inside a heel strike, or a second
// D in the same stance) stays inside its run and is then dropped as too short.
TEST(ZuptDetector, ShortWholeStepIsWidenedOthersAreNot) {
  //                  0         1         2         3         4         5         6         7
  //                  0123456789012345678901234567890123456789012345678901234567890123456789012345678
  const char* gait = "DDDDDDDDDDAAAABBBBBBBBBBBBCCCDDAAAABBBBBBBBBBCCCCDCCCCDDDDDDCCCDDAAAABBBB";
  // D 0-9; A, B; C 26-28; D 29-30 (a whole step, 20 ms); A, B; C 45-48, D 49 (inside a heel strike), C 50-53;
  // D 54-59; C 60-62, D 63-64 (no swing since the stance at 54-59); A, B.
  std::vector<ImuSample> s;
  std::vector<ZuptDecision> d;
  gait_from_string(gait, s, d);
  std::vector<double> T;  // the foot never stops: T above γ = 10 everywhere
  for (int k = 0; gait[k] != '\0'; ++k) T.push_back(gait[k] == 'D' ? 20.0 : 60.0 + k % 3);
  ZuptDetectorOptions o;
  o.hmm_refine_factor = 2.0;
  o.min_stance_s = 0.04;
  refine_hmm_stances(d, s, T, o);
  auto stance = [&](int a, int b) {
    std::string r;
    for (int k = a; k <= b; ++k) r += d[static_cast<std::size_t>(k)].stance ? '1' : '0';
    return r;
  };
  EXPECT_EQ(stance(0, 9), "1111111111");  // long enough: its T < 40 core is the whole run
  // The whole step (29-30, 10 ms): widened beyond its run to 40 ms = 5 samples, contiguous, inside the swings.
  const std::string step = stance(14, 44);
  EXPECT_EQ(std::count(step.begin(), step.end(), '1'), 5) << step;
  EXPECT_NE(step.find("11111"), std::string::npos) << step;
  EXPECT_TRUE(d[29].stance && d[30].stance);
  EXPECT_EQ(stance(45, 53), "000010000");  // a D inside a heel strike: not widened (drop_short_runs removes it)
  EXPECT_EQ(stance(54, 59), "111111");
  EXPECT_EQ(stance(60, 66), "0001100");    // a second D of the same stance (no swing since 54-59): not widened
}

// refine_hmm_stances outside the core: a foot that rocks on heel and toe has two still parts in one decoded stance.
// The core is the part around the smallest T; the other part's samples with T < γ are stance too (a ZUPT may use
// them), the samples between them are not, and stance_phases() still counts one footfall. A gap that is not decoded
// stance (a push-off) separates footfalls.
TEST(ZuptDetector, HmmRefineKeepsEveryStillPartOfTheDecodedStance) {
  //                  0         1         2         3
  //                  0123456789012345678901234567890123456789
  const char* gait = "AABBBBBCCDDDDDDDDDDDDDDDDDDDDAAAABBBCCDDDDD";
  // A, B, C; D 9-28 (one decoded stance); A 29-32, B, C; D 38-42.
  std::vector<ImuSample> s;
  std::vector<ZuptDecision> d;
  gait_from_string(gait, s, d);
  std::vector<double> T(s.size(), 60.0);
  for (int k = 9; k <= 28; ++k) T[static_cast<std::size_t>(k)] = 25.0;          // rolling
  for (int k = 10; k <= 14; ++k) T[static_cast<std::size_t>(k)] = 2.0 + 0.1 * k;   // heel flat: the core (T_min 3)
  for (int k = 19; k <= 25; ++k) T[static_cast<std::size_t>(k)] = 7.0;             // toe flat: T < γ = 10
  for (int k = 38; k <= 42; ++k) T[static_cast<std::size_t>(k)] = 4.0;
  ZuptDetectorOptions o;
  o.hmm_refine_factor = 2.0;
  o.min_stance_s = 0.04;
  refine_hmm_stances(d, s, T, o);
  std::string r;
  for (const auto& x : d) r += x.stance ? '1' : '0';
  EXPECT_EQ(r.substr(9, 20), "01111100001111111000") << r;  // both still parts, not the roll between them
  const auto phases = stance_phases(d);
  ASSERT_EQ(phases.size(), 2u) << r;
  EXPECT_EQ(phases[0], std::make_pair(std::size_t{10}, std::size_t{25}));
  EXPECT_EQ(phases[1], std::make_pair(std::size_t{38}, std::size_t{42}));
  // Without HMM states (another detector) every stance run is a footfall.
  for (auto& x : d) x.gait_state = -1;
  EXPECT_EQ(stance_phases(d).size(), 3u);
}

}  // namespace
}  // namespace pednav::ins

namespace pednav::ins {
namespace {

// zupt_update_samples (docs/zupt.md §5) at 100 Hz: a 0.30-s stance loses 20 ms at each end; a 50-ms stance is
// shorter than its edges and keeps its central min_core_s (30 ms here); a single-sample stance keeps that sample;
// edge 0 returns the stance flags themselves.
TEST(ZuptDetector, UpdateSamplesSkipTheStanceEdges) {
  std::vector<ImuSample> s(100);
  std::vector<ZuptDecision> d(100);
  for (int k = 0; k < 100; ++k) s[k].t = GpsTime::from_week_tow(0, k / 100.0);
  for (int k = 10; k <= 39; ++k) d[k].stance = true;  // 0.29 s from first to last sample
  for (int k = 50; k <= 55; ++k) d[k].stance = true;  // 0.05 s
  d[70].stance = true;
  const std::vector<bool> ok = zupt_update_samples(d, s, 0.02, 0.03);
  for (int k = 0; k < 100; ++k) {
    bool expected = (k >= 12 && k <= 37) || (k >= 51 && k <= 54) || k == 70;
    if (k >= 51 && k <= 54) expected = std::abs(k / 100.0 - 0.525) <= 0.015 + 1e-9;  // centre 0.525 s ± 15 ms
    EXPECT_EQ(ok[k], expected) << "sample " << k;
  }
  const std::vector<bool> flags = zupt_update_samples(d, s, 0.0, 0.03);
  for (int k = 0; k < 100; ++k) EXPECT_EQ(flags[k], d[k].stance) << "sample " << k;
}

// zupt_forced_interval_ends (docs/zupt.md §5) at 200 Hz with a 20-Hz grid (50 ms): samples at 2.5 ms + 5 ms k, so
// sample k completes a grid interval when k = 10 j (grid point 50 j ms lies between samples 10 j − 1 and 10 j).
// A 25-ms stance between two grid points gets its middle sample; a stance that spans a grid point does not; a stance
// whose grid-completing sample is not usable (ok false) gets the middle of its usable samples; a stance without a
// usable sample gets nothing.
TEST(ZuptDetector, ShortStancesWithoutAnIntervalEndGetOne) {
  const int n = 100;
  std::vector<ImuSample> s(n);
  std::vector<ZuptDecision> d(n);
  for (int k = 0; k < n; ++k) s[k].t = GpsTime::from_ns(2'500'000LL + 5'000'000LL * k);
  const int64_t period = 50'000'000;
  for (int k = 12; k <= 16; ++k) d[k].stance = true;  // 62.5-82.5 ms: no grid point (50, 100 ms) inside
  for (int k = 28; k <= 33; ++k) d[k].stance = true;  // 142.5-167.5 ms: sample 30 (152.5 ms) completes 150 ms
  for (int k = 48; k <= 53; ++k) d[k].stance = true;  // sample 50 completes 250 ms, but only 51-53 are usable
  for (int k = 70; k <= 72; ++k) d[k].stance = true;  // no usable sample
  std::vector<bool> ok(n, false);
  for (int k = 0; k < n; ++k) ok[k] = d[k].stance && !(k >= 48 && k <= 50) && !(k >= 70 && k <= 72);
  const std::vector<bool> cut = zupt_forced_interval_ends(d, ok, s, period);
  for (int k = 0; k < n; ++k) EXPECT_EQ(cut[k], k == 14 || k == 52) << "sample " << k;
  // No stance at all, or a non-positive period: nothing to cut.
  const std::vector<bool> none = zupt_forced_interval_ends(std::vector<ZuptDecision>(n), ok, s, period);
  EXPECT_EQ(std::count(none.begin(), none.end(), true), 0);
  const std::vector<bool> bad = zupt_forced_interval_ends(d, ok, s, 0);
  EXPECT_EQ(std::count(bad.begin(), bad.end(), true), 0);
}

}  // namespace
}  // namespace pednav::ins
