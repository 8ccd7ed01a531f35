// SPDX-License-Identifier: BSD-2-Clause
// eval/outage.* and eval/statistics.*: window placement, which satellites a partial outage keeps (seed 004:
// drop the lowest elevation while more than N remain), per-window figures, RMS across windows vs time since the
// outage started (seed 004 Figure 17), CDF, per-segment and vertical statistics.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "eval/outage.hpp"
#include "eval/statistics.hpp"

namespace pednav::eval {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
constexpr double kTol_s = 1e-9;
constexpr double kTol_m = 1e-12;
const GpsTime kT0 = GpsTime::from_week_tow(2300, 225000.0);

TEST(OutageWindows, EvenlyPlacedAreCentredInEqualSlots) {
  // 1000 s span, 5 slots of 200 s, 100 s windows centred: starts at 50, 250, 450, 650, 850 s.
  auto w = place_windows_evenly(kT0, kT0.plus_s(1000.0), 5, 100.0);
  ASSERT_TRUE(w.has_value()) << w.error().message;
  ASSERT_EQ(w->size(), 5u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR((*w)[k].start - kT0, 50.0 + 200.0 * k, kTol_s) << k;
    EXPECT_NEAR((*w)[k].duration_s, 100.0, kTol_s);
  }
  EXPECT_TRUE((*w)[0].contains(kT0.plus_s(50.0)));
  EXPECT_TRUE((*w)[0].contains(kT0.plus_s(149.9)));
  EXPECT_FALSE((*w)[0].contains(kT0.plus_s(150.0)));
  EXPECT_FALSE((*w)[0].contains(kT0.plus_s(49.9)));
}

TEST(OutageWindows, TooManyWindowsNameTheSpan) {
  auto w = place_windows_evenly(kT0, kT0.plus_s(450.0), 5, 100.0);
  ASSERT_FALSE(w.has_value());
  EXPECT_THAT(w.error().message, HasSubstr("5 x 100 s do not fit in the 450 s"));
  EXPECT_THAT(place_windows_evenly(kT0, kT0.plus_s(450.0), 0, 10.0).error().message, HasSubstr("count must be >= 1"));
}

TEST(OutageWindows, ExplicitStartsMustNotOverlap) {
  auto ok = explicit_windows({kT0, kT0.plus_s(100.0)}, 100.0);
  ASSERT_TRUE(ok.has_value());
  EXPECT_EQ(ok->size(), 2u);
  auto bad = explicit_windows({kT0, kT0.plus_s(99.0)}, 100.0);
  ASSERT_FALSE(bad.has_value());
  EXPECT_THAT(bad.error().message, HasSubstr("less than the duration"));
  EXPECT_THAT(explicit_windows({}, 100.0).error().message, HasSubstr("no start time"));
}

TEST(KeptSatellites, DropsLowestElevationWhileMoreThanNRemain) {
  const std::vector<SatCandidate> c{{1, 0.9, 30}, {2, 0.2, 50}, {3, 1.2, 20}, {4, 0.5, 45}, {5, 0.3, 40}};
  EXPECT_THAT(select_kept_satellites(c, 3, KeepBy::kElevation), ElementsAre(1, 3, 4));
  EXPECT_THAT(select_kept_satellites(c, 2, KeepBy::kElevation), ElementsAre(1, 3));
  EXPECT_THAT(select_kept_satellites(c, 2, KeepBy::kCn0), ElementsAre(2, 4));
  EXPECT_THAT(select_kept_satellites(c, 9, KeepBy::kElevation), ElementsAre(1, 2, 3, 4, 5));  // fewer than N: all
  EXPECT_TRUE(select_kept_satellites(c, 0, KeepBy::kElevation).empty());                       // full outage
}

TEST(KeptSatellites, UnknownCn0IsWeakestAndTiesGoByIdentifier) {
  const std::vector<SatCandidate> c{{7, 0.5, NAN}, {3, 0.5, 35}, {9, 0.5, 35}};
  EXPECT_THAT(select_kept_satellites(c, 1, KeepBy::kCn0), ElementsAre(3));
  EXPECT_THAT(select_kept_satellites(c, 2, KeepBy::kElevation), ElementsAre(3, 7));
}

TEST(OutageErrors, WindowStatsAndRmsAcrossWindows) {
  // Window A: error = t/10 at t = 0..10 s; window B: error = 2 * t/10, sampled at 0.5 s offsets + one at 10 s.
  WindowErrors a, b;
  for (int i = 0; i <= 10; ++i) {
    a.t_since_s.push_back(i);
    a.horizontal_m.push_back(i / 10.0);
  }
  for (int i = 0; i < 10; ++i) {
    b.t_since_s.push_back(i + 0.25);
    b.horizontal_m.push_back(2.0 * i / 10.0);
  }
  b.t_since_s.push_back(10.0);
  b.horizontal_m.push_back(3.0);
  const WindowStats sa = window_stats(a), sb = window_stats(b);
  EXPECT_EQ(sa.samples, 11);
  EXPECT_NEAR(sa.max_m, 1.0, kTol_m);
  EXPECT_NEAR(sa.end_m, 1.0, kTol_m);
  EXPECT_NEAR(sb.max_m, 3.0, kTol_m);
  EXPECT_NEAR(sb.end_t_since_s, 10.0, kTol_s);
  const RmsVsTime r = rms_vs_time({a, b}, 1.0);
  ASSERT_EQ(r.t_since_s.size(), 11u);
  for (int k = 0; k < 10; ++k) {
    EXPECT_NEAR(r.t_since_s[k], k, kTol_s);
    EXPECT_EQ(r.n_windows[k], 2) << k;
    const double ea = k / 10.0, eb = 2.0 * k / 10.0;
    EXPECT_NEAR(r.rms_m[k], std::sqrt((ea * ea + eb * eb) / 2.0), kTol_m) << k;
  }
  EXPECT_NEAR(r.rms_m[10], std::sqrt((1.0 + 9.0) / 2.0), kTol_m);
  // A window with no sample in a bin does not count there.
  WindowErrors c;
  c.t_since_s = {3.0};
  c.horizontal_m = {4.0};
  const RmsVsTime r2 = rms_vs_time({a, c}, 1.0);
  EXPECT_EQ(r2.n_windows[3], 2);
  EXPECT_EQ(r2.n_windows[4], 1);
  EXPECT_NEAR(r2.rms_m[4], 0.4, kTol_m);
}

// The solution's own σ is reported at the sample of the largest error and at the window's end; without σ
// (or with a σ series of another length) both stay NaN.
TEST(OutageErrors, WindowStatsCarryTheSigmaAtTheMaximumAndAtTheEnd) {
  WindowErrors w;
  w.t_since_s = {0.0, 1.0, 2.0, 3.0};
  w.horizontal_m = {0.5, 2.5, 1.0, 0.7};
  const WindowStats none = window_stats(w);
  EXPECT_TRUE(std::isnan(none.sigma_at_max_m));
  EXPECT_TRUE(std::isnan(none.end_sigma_m));
  w.sigma_horizontal_m = {0.4, 1.6, 1.9, 2.2};
  const WindowStats s = window_stats(w);
  EXPECT_NEAR(s.max_m, 2.5, kTol_m);
  EXPECT_NEAR(s.sigma_at_max_m, 1.6, kTol_m) << "sigma of the sample with the largest error, not the largest sigma";
  EXPECT_NEAR(s.end_sigma_m, 2.2, kTol_m);
  w.sigma_horizontal_m.pop_back();
  EXPECT_TRUE(std::isnan(window_stats(w).sigma_at_max_m)) << "a sigma series that does not match is not used";
}

TEST(OutageErrors, EmpiricalCdf) {
  const Cdf c = empirical_cdf({3.0, 1.0, 2.0, 4.0});
  EXPECT_THAT(c.value, ElementsAre(1.0, 2.0, 3.0, 4.0));
  EXPECT_THAT(c.fraction, ElementsAre(0.25, 0.5, 0.75, 1.0));
  EXPECT_TRUE(empirical_cdf({}).value.empty());
}

TEST(Statistics, SegmentsAndVertical) {
  std::vector<EpochError> e;
  for (int i = 0; i < 25; ++i) {  // 0..24 s; segments of 10 s: 10, 10, 5 epochs
    EpochError x;
    x.t = kT0.plus_s(i);
    const double h = i < 10 ? 1.0 : (i < 20 ? 2.0 : 3.0);
    x.d_enu = Eigen::Vector3d(h, 0.0, i % 2 == 0 ? 0.5 : -0.5);
    x.horizontal_m = h;
    e.push_back(x);
  }
  const auto s = segment_statistics(e, 10.0);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0].epochs, 10);
  EXPECT_EQ(s[2].epochs, 5);
  EXPECT_NEAR(s[1].horizontal_rms_m, 2.0, kTol_m);
  EXPECT_NEAR(s[2].horizontal_max_m, 3.0, kTol_m);
  EXPECT_NEAR(s[0].horizontal_mean_e_m, 1.0, kTol_m);
  EXPECT_NEAR(s[0].vertical_rms_m, 0.5, kTol_m);
  EXPECT_NEAR(s[2].t_end - kT0, 24.0, kTol_s);
  const VerticalStats v = vertical_statistics(e);
  EXPECT_NEAR(v.rms_m, 0.5, kTol_m);
  EXPECT_NEAR(v.mean_m, 0.5 / 25.0, kTol_m);  // 13 x +0.5, 12 x -0.5
  EXPECT_NEAR(v.max_abs_m, 0.5, kTol_m);
}

// Consistency of the solution's own σ (evaluation.json "consistency"): known normalized errors.
TEST(Statistics, ConsistencyOfTheSolutionSigma) {
  std::vector<EpochError> e;
  // 10 epochs with σ_E = 2, σ_N = 1, σ_U = 0.5 and normalized errors (q_E, q_N) = (1, 1) x 8, (4, 0), (0, -3.5);
  // vertical errors 0.5 (1σ) x 9 and 2.0 (4σ); one epoch without σ (ignored).
  for (int i = 0; i < 11; ++i) {
    EpochError x;
    x.t = kT0.plus_s(i);
    double qe = 1.0, qn = 1.0;
    if (i == 8) qe = 4.0, qn = 0.0;
    if (i == 9) qe = 0.0, qn = -3.5;
    x.sd_enu_m = Eigen::Vector3d(2.0, 1.0, 0.5);
    x.d_enu = Eigen::Vector3d(qe * 2.0, qn * 1.0, i == 0 ? 2.0 : 0.5);
    if (i == 10) x.sd_enu_m.setConstant(std::nan(""));
    e.push_back(x);
  }
  const ConsistencyStats c = consistency_statistics(e);
  EXPECT_EQ(c.epochs, 10);
  EXPECT_NEAR(c.inside_3sigma_pct, 80.0, kTol_m);
  EXPECT_NEAR(c.inside_3sigma_vertical_pct, 90.0, kTol_m);
  EXPECT_NEAR(c.mean_normalized_sq_horizontal, (8 * 2.0 + 16.0 + 12.25) / 10.0, kTol_m);
  EXPECT_NEAR(c.max_normalized_horizontal, 4.0, kTol_m);
  EXPECT_EQ(consistency_statistics({}).epochs, 0);
}

}  // namespace
}  // namespace pednav::eval
