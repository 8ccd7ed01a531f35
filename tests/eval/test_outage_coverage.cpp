// SPDX-License-Identifier: BSD-2-Clause
// Outage windows placed where a reference covers them (eval::place_windows_covered, issue 49 item 8).
#include <gtest/gtest.h>

#include <vector>

#include "eval/outage.hpp"

namespace pednav::eval {
namespace {

const GpsTime kT0 = GpsTime::from_week_tow(2000, 100000.0);

// 1 Hz reference epochs over [from_s, to_s] (seconds after kT0), without those in the open interval (gap_from, gap_to).
ReferenceCoverage reference(double from_s, double to_s, double gap_from_s = 1e9, double gap_to_s = -1e9) {
  ReferenceCoverage r;
  for (double s = from_s; s <= to_s; s += 1.0) {
    if (s > gap_from_s && s < gap_to_s) continue;
    r.epochs.push_back(kT0.plus_s(s));
  }
  return r;
}

TEST(ReferenceCoverage, CountsTheBridgedSpansInsideTheInterval) {
  const ReferenceCoverage r = reference(0, 10, 3, 8);  // epochs 0..3 and 8..10; the 5-s gap is not bridged
  EXPECT_NEAR(r.covered_s(kT0, kT0.plus_s(10)), 3.0 + 2.0, 1e-9);
  EXPECT_NEAR(r.covered_s(kT0.plus_s(2.5), kT0.plus_s(9)), 0.5 + 1.0, 1e-9);
  EXPECT_NEAR(r.covered_s(kT0.plus_s(4), kT0.plus_s(7)), 0.0, 1e-9);
  EXPECT_NEAR(r.covered_s(kT0.plus_s(-5), kT0.plus_s(20)), 5.0, 1e-9) << "nothing outside the reference";
}

TEST(PlaceWindowsCovered, AFullyCoveringReferenceGivesTheEvenPlacement) {
  const GpsTime from = kT0.plus_s(30), to = kT0.plus_s(530);
  auto even = place_windows_evenly(from, to, 4, 60.0);
  auto covered = place_windows_covered(from, to, 4, 60.0, reference(0, 600));
  ASSERT_TRUE(even.has_value() && covered.has_value());
  ASSERT_EQ(covered->size(), 4u);
  for (size_t k = 0; k < 4; ++k) EXPECT_EQ((*covered)[k].start, (*even)[k].start) << k;
}

TEST(PlaceWindowsCovered, AWindowOnAGapMovesWithinItsSlotToTheLongestCover) {
  const GpsTime from = kT0, to = kT0.plus_s(400);  // 2 slots of 200 s; centred windows at 70 and 270 s
  // A gap over 60..160 s: in slot 1 [0, 200] the window [0, 60] is fully covered, any later one at most 40 s.
  auto w = place_windows_covered(from, to, 2, 60.0, reference(0, 400, 60, 160));
  ASSERT_TRUE(w.has_value());
  EXPECT_NEAR((*w)[0].start - from, 0.0, 1e-9);
  EXPECT_NEAR((*w)[1].start - from, 270.0, 1e-9) << "slot 2 is covered: centred";
  // A gap over 50..130 s: [0, 60] covers 50 s, every start in 130..140 s covers 60 s; of those, the one nearest the
  // centred start (70 s) wins.
  const ReferenceCoverage r = reference(0, 400, 50, 130);
  auto near = place_windows_covered(from, to, 2, 60.0, r);
  ASSERT_TRUE(near.has_value());
  EXPECT_NEAR((*near)[0].start - from, 130.0, 1e-9);
  EXPECT_NEAR(r.covered_s((*near)[0].start, (*near)[0].end()), 60.0, 1e-9);
}

TEST(PlaceWindowsCovered, ASlotTheReferenceNeverReachesKeepsItsCentredWindow) {
  const GpsTime from = kT0, to = kT0.plus_s(400);
  const ReferenceCoverage r = reference(0, 180);  // nothing in slot 2 [200, 400]
  auto w = place_windows_covered(from, to, 2, 60.0, r);
  ASSERT_TRUE(w.has_value());
  EXPECT_NEAR((*w)[1].start - from, 270.0, 1e-9);
  EXPECT_EQ(r.covered_s((*w)[1].start, (*w)[1].end()), 0.0);
  EXPECT_FALSE(place_windows_covered(from, to, 10, 60.0, r).has_value()) << "10 x 60 s do not fit in 400 s";
}

}  // namespace
}  // namespace pednav::eval
