// SPDX-License-Identifier: BSD-2-Clause
#include <gtest/gtest.h>

#include "core/time.hpp"

namespace pednav {
namespace {

TEST(GpsTime, WeekAndTowRoundTrip) {
  const GpsTime t = GpsTime::from_week_tow(2024, 345600.123456789);
  EXPECT_EQ(t.week(), 2024);
  EXPECT_NEAR(t.tow_s(), 345600.123456789, 1e-9);
  EXPECT_EQ(t.ns(), 2024LL * kNsPerWeek + 345600123456789LL);
}

TEST(GpsTime, CalendarOfKnownEpochs) {
  // 2018-10-04 15:33:40 GPST (Galway walk start) = GPS week 2021, Thursday.
  const GpsTime t = GpsTime::from_calendar_gpst({2018, 10, 4, 15, 33, 40.987});
  EXPECT_EQ(t.week(), 2021);
  EXPECT_NEAR(t.tow_s(), 4 * 86400 + 15 * 3600 + 33 * 60 + 40.987, 1e-9);
  const CalendarTime c = t.to_calendar_gpst();
  EXPECT_EQ(c.year, 2018);
  EXPECT_EQ(c.month, 10);
  EXPECT_EQ(c.day, 4);
  EXPECT_EQ(c.hour, 15);
  EXPECT_EQ(c.minute, 33);
  EXPECT_NEAR(c.second, 40.987, 1e-9);
  EXPECT_EQ(t.to_string(), "2018-10-04 15:33:40.987 GPST");
  // The GPS epoch itself.
  EXPECT_EQ(GpsTime::from_calendar_gpst({1980, 1, 6, 0, 0, 0.0}).ns(), 0);
}

TEST(GpsTime, UtcUsesLeapSeconds) {
  // 2018: GPS - UTC = 18 s.
  const GpsTime t = GpsTime::from_utc({2018, 10, 4, 15, 33, 22.0});
  EXPECT_EQ(t, GpsTime::from_calendar_gpst({2018, 10, 4, 15, 33, 40.0}));
  EXPECT_EQ(gps_minus_utc_s(t), 18);
  const CalendarTime u = t.to_utc();
  EXPECT_EQ(u.hour, 15);
  EXPECT_EQ(u.minute, 33);
  EXPECT_NEAR(u.second, 22.0, 1e-9);
  // 2005 (GEONET sample): 13 s; 2016-12-31 23:59:59 UTC: 17 s, 2017-01-01 00:00:00 UTC: 18 s.
  EXPECT_EQ(gps_minus_utc_s(GpsTime::from_utc({2005, 4, 2, 0, 0, 0.0})), 13);
  EXPECT_EQ(gps_minus_utc_s(GpsTime::from_utc({2016, 12, 31, 23, 59, 59.0})), 17);
  EXPECT_EQ(gps_minus_utc_s(GpsTime::from_utc({2017, 1, 1, 0, 0, 0.0})), 18);
}

TEST(GpsTime, ArithmeticAndOrdering) {
  const GpsTime a = GpsTime::from_week_tow(2021, 604799.5);
  const GpsTime b = a.plus_s(1.0);  // crosses the week boundary
  EXPECT_EQ(b.week(), 2022);
  EXPECT_NEAR(b.tow_s(), 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(b - a, 1.0);
  EXPECT_LT(a, b);
  EXPECT_EQ(a.plus_ns(1) - a, 1e-9);
}

TEST(GpsTime, NegativeTimesFloorCorrectly) {
  const GpsTime t = GpsTime::from_ns(-1);
  EXPECT_EQ(t.week(), -1);
  EXPECT_NEAR(t.tow_s(), 604800.0 - 1e-9, 1e-9);
}

}  // namespace
}  // namespace pednav
