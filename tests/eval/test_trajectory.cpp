// SPDX-License-Identifier: BSD-2-Clause
#include <cmath>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "eval/trajectory.hpp"

namespace pednav::eval {
namespace {

using ::testing::HasSubstr;
constexpr double kTol_m = 1e-6;

const Eigen::Vector3d kOrigin_e = ecef_from_geodetic({53.28 * kDegToRad, -9.06 * kDegToRad, 60.0});

// A 1 Hz walk along a square in ENU about kOrigin_e.
Trajectory square_walk(int n, double offset_e_m = 0.0, double offset_n_m = 0.0, double offset_u_m = 0.0) {
  Trajectory t;
  const GpsTime t0 = GpsTime::from_week_tow(2021, 400000.0);
  for (int i = 0; i < n; ++i) {
    const double s = i % 40;
    Eigen::Vector3d enu = (i / 10) % 4 == 0 ? Eigen::Vector3d(s, 0, 0) : Eigen::Vector3d(10.0, s, 0);
    enu += Eigen::Vector3d(offset_e_m, offset_n_m, offset_u_m);
    t.points.push_back({t0.plus_s(i), ecef_from_ned(Eigen::Vector3d(enu.y(), enu.x(), -enu.z()), kOrigin_e)});
  }
  return t;
}

TEST(Compare, ConstantOffsetGivesExactStatistics) {
  const Trajectory ref = square_walk(100);
  const Trajectory sol = square_walk(100, 3.0, 6.0, -1.0);
  auto ev = compare(sol, ref, CompareOptions{});
  ASSERT_TRUE(ev) << ev.error().message;
  EXPECT_EQ(ev->epochs_compared, 100);
  EXPECT_NEAR(ev->availability_pct, 100.0, 1e-9);
  const double expected_m = std::sqrt(45.0);
  EXPECT_NEAR(ev->horizontal_rms_m, expected_m, 1e-4);
  EXPECT_NEAR(ev->horizontal_max_m, expected_m, 1e-4);
  EXPECT_NEAR(ev->horizontal_p95_m, expected_m, 1e-4);
  EXPECT_NEAR(ev->vertical_rms_m, 1.0, 1e-4);
  EXPECT_NEAR(ev->vertical_mean_m, -1.0, 1e-4);
  EXPECT_NEAR(ev->errors[10].d_enu.x(), 3.0, 1e-4);
  EXPECT_NEAR(ev->bins_pct[1], 100.0, 1e-9);  // 6.7 m falls in the 5-10 m bin
}

TEST(Compare, BinsAndQuantiles) {
  EXPECT_DOUBLE_EQ(quantile({1, 2, 3, 4, 5}, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(quantile({1, 2, 3, 4}, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(quantile({7}, 0.95), 7.0);
  Trajectory ref = square_walk(4), sol = ref;
  const double offsets[4] = {1.0, 7.0, 15.0, 30.0};
  for (int i = 0; i < 4; ++i) sol.points[i].p = ecef_from_ned(Eigen::Vector3d(offsets[i], 0, 0), ref.points[i].p);
  auto ev = compare(sol, ref, CompareOptions{});
  ASSERT_TRUE(ev);
  for (int b = 0; b < 4; ++b) EXPECT_NEAR(ev->bins_pct[b], 25.0, 1e-9);
}

TEST(Compare, MissingSolutionEpochsLowerAvailability) {
  const Trajectory ref = square_walk(100);
  Trajectory sol = ref;
  sol.points.erase(sol.points.begin() + 40, sol.points.begin() + 50);  // a 10 s hole
  auto ev = compare(sol, ref, CompareOptions{});
  ASSERT_TRUE(ev);
  EXPECT_NEAR(ev->availability_pct, 90.0, 1e-9);
  EXPECT_EQ(ev->epochs_compared, 90);
}

TEST(Compare, ReferenceIsInterpolatedBetweenCloseEpochs) {
  const Trajectory ref = square_walk(20);
  Trajectory sol;
  for (size_t i = 0; i + 1 < 9; ++i) {  // solution at half seconds, on the straight first leg
    const auto& a = ref.points[i];
    const auto& b = ref.points[i + 1];
    sol.points.push_back({a.t.plus_s(0.5), 0.5 * (a.p + b.p)});
  }
  auto ev = compare(sol, ref, CompareOptions{});
  ASSERT_TRUE(ev);
  EXPECT_EQ(ev->epochs_compared, 8);
  EXPECT_LT(ev->horizontal_max_m, kTol_m);
}

TEST(Compare, NoOverlapNamesBothSpans) {
  const Trajectory ref = square_walk(10);
  Trajectory sol = ref;
  for (auto& p : sol.points) p.t = p.t.plus_s(3600.0);
  auto ev = compare(sol, ref, CompareOptions{});
  ASSERT_FALSE(ev);
  EXPECT_THAT(ev.error().message, HasSubstr("no overlapping epochs: solution 2018-10-04"));
  EXPECT_THAT(ev.error().message, HasSubstr("reference 2018-10-04"));
}

// A local-frame reference (like Vicon) rotated and shifted from the solution's ENU.
Trajectory local_reference(const Trajectory& sol_ecef, double yaw, const Eigen::Vector3d& shift) {
  Trajectory ref;
  ref.frame = Frame::kLocalEnu;
  const Eigen::Matrix3d rz = so3_exp(Eigen::Vector3d(0, 0, yaw));
  for (const auto& p : sol_ecef.points) ref.points.push_back({p.t, rz * enu_from_ecef(p.p, sol_ecef.points.front().p) + shift});
  return ref;
}

TEST(Compare, AlignmentRecoversRotationAndTranslation) {
  const Trajectory sol = square_walk(60);
  const Trajectory ref = local_reference(sol, 0.7, Eigen::Vector3d(5.0, -2.0, 1.0));
  CompareOptions o;
  auto none = compare(sol, ref, o);
  ASSERT_FALSE(none);
  EXPECT_THAT(none.error().message, HasSubstr("local frame"));
  for (Align a : {Align::kStart, Align::kStartPyshoe, Align::kBestFit2d, Align::kBestFit3d}) {
    o.align = a;
    auto ev = compare(sol, ref, o);
    ASSERT_TRUE(ev) << ev.error().message;
    EXPECT_LT(ev->horizontal_max_m, 1e-6) << static_cast<int>(a);
    EXPECT_LT(std::abs(ev->vertical_mean_m), 1e-6);
  }
}

// start vs start-pyshoe: `start` takes the direction at the first *reference* point >= 1 m out, `start-pyshoe`
// (PyShoe's align_plots) at the first *solution* epoch >= 0.8 m out, else 1.5 s after the start.
TEST(Compare, StartAlignmentsPickTheirEpochs) {
  const GpsTime t0 = GpsTime::from_week_tow(2021, 400000.0);
  auto track = [&](const std::vector<Eigen::Vector2d>& en, Frame f) {
    Trajectory t;
    t.frame = f;
    for (size_t i = 0; i < en.size(); ++i) {
      const Eigen::Vector3d enu(en[i].x(), en[i].y(), 0.0);
      t.points.push_back({t0.plus_s(static_cast<double>(i)),
                          f == Frame::kEcef ? ecef_from_ned(Eigen::Vector3d(enu.y(), enu.x(), 0.0), kOrigin_e) : enu});
    }
    return t;
  };
  const Trajectory ref = track({{0, 0}, {1, 0}, {2, 0}, {3, 0}, {4, 0}}, Frame::kLocalEnu);
  const Trajectory sol = track({{0, 0}, {0.5, 0}, {0.7, 0.7}, {2, 0}, {3, 0}}, Frame::kEcef);
  auto yaw_deg = [](const Evaluation& ev) { return std::atan2(ev.R_align(1, 0), ev.R_align(0, 0)) * kRadToDeg; };
  CompareOptions o;
  o.align = Align::kStart;
  auto a = compare(sol, ref, o);
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_NEAR(yaw_deg(*a), 0.0, 1e-6);  // reference point 1: (1, 0) against (0.5, 0)
  o.align = Align::kStartPyshoe;
  auto b = compare(sol, ref, o);
  ASSERT_TRUE(b) << b.error().message;
  EXPECT_NEAR(yaw_deg(*b), -45.0, 1e-6);  // solution epoch 2 (0.99 m out): (2, 0) against (0.7, 0.7)
  // A solution that never gets 0.8 m out: the epoch 1.5 s after the start (epoch 2).
  const Trajectory stay = track({{0, 0}, {0.1, 0}, {0.3, 0.3}, {0.2, 0}, {0.1, 0}}, Frame::kEcef);
  auto c = compare(stay, ref, o);
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_NEAR(yaw_deg(*c), -45.0, 1e-6);
}

TEST(Compare, LoopClosure) {
  Trajectory sol = square_walk(41);  // 10 m east, then north 10 m... ends back on the first leg
  CompareOptions o;
  o.loop = true;
  auto ev = compare(sol, sol, o);
  ASSERT_TRUE(ev);
  ASSERT_TRUE(ev->has_closure);
  EXPECT_GT(ev->distance_m, 0.0);
  const Eigen::Vector3d d = enu_from_ecef(sol.points.back().p, sol.points.front().p);
  EXPECT_NEAR(ev->closure_m, d.head<2>().norm(), 1e-9);
  EXPECT_NEAR(ev->closure_pct_of_distance, 100.0 * ev->closure_m / ev->distance_m, 1e-9);
}

}  // namespace
}  // namespace pednav::eval
