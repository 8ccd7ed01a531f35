// SPDX-License-Identifier: BSD-2-Clause
#include "core/time.hpp"

#include <array>
#include <cmath>
#include <cstdio>

namespace pednav {
namespace {

constexpr int64_t kGpsEpochUnixDays = 3657;  // 1980-01-06 is 3657 days after 1970-01-01

// Leap seconds: (UTC date of the first day with the new value, GPS-UTC after it).
struct Leap {
  int year, month, day, gps_minus_utc;
};
constexpr std::array<Leap, 18> kLeaps{{{1981, 7, 1, 1},  {1982, 7, 1, 2},  {1983, 7, 1, 3},  {1985, 7, 1, 4},
                                       {1988, 1, 1, 5},  {1990, 1, 1, 6},  {1991, 1, 1, 7},  {1992, 7, 1, 8},
                                       {1993, 7, 1, 9},  {1994, 7, 1, 10}, {1996, 1, 1, 11}, {1997, 7, 1, 12},
                                       {1999, 1, 1, 13}, {2006, 1, 1, 14}, {2009, 1, 1, 15}, {2012, 7, 1, 16},
                                       {2015, 7, 1, 17}, {2017, 1, 1, 18}}};

int64_t round_to_ns(double s) { return static_cast<int64_t>(std::llround(s * 1e9)); }

void civil_from_days(int64_t z, int& y, int& m, int& d) {
  // H. Hinnant's civil_from_days (public-domain algorithm description).
  z += 719468;
  const int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const int64_t doe = z - era * 146097;
  const int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const int64_t mp = (5 * doy + 2) / 153;
  d = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  m = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  y = static_cast<int>(yoe + era * 400 + (m <= 2 ? 1 : 0));
}

CalendarTime calendar_from_ns(int64_t ns_since_gps_epoch) {
  const int64_t ns_per_day = 86400 * kNsPerS;
  int64_t days = ns_since_gps_epoch / ns_per_day;
  int64_t rem = ns_since_gps_epoch % ns_per_day;
  if (rem < 0) {
    rem += ns_per_day;
    --days;
  }
  CalendarTime c;
  civil_from_days(days + kGpsEpochUnixDays, c.year, c.month, c.day);
  const int64_t sod_s = rem / kNsPerS;
  c.hour = static_cast<int>(sod_s / 3600);
  c.minute = static_cast<int>((sod_s % 3600) / 60);
  c.second = static_cast<double>(sod_s % 60) + static_cast<double>(rem % kNsPerS) * 1e-9;
  return c;
}

}  // namespace

int64_t days_from_civil(int year, int month, int day) {
  const int64_t y = year - (month <= 2 ? 1 : 0);
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const int64_t yoe = y - era * 400;
  const int64_t doy = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
  const int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

GpsTime GpsTime::from_week_tow(int week, double tow_s) {
  return from_ns(static_cast<int64_t>(week) * kNsPerWeek + round_to_ns(tow_s));
}

GpsTime GpsTime::from_seconds(double s) { return from_ns(round_to_ns(s)); }

GpsTime GpsTime::from_calendar_gpst(const CalendarTime& c) {
  const int64_t days = days_from_civil(c.year, c.month, c.day) - kGpsEpochUnixDays;
  const int64_t whole_s = days * 86400 + c.hour * 3600 + c.minute * 60;
  return from_ns(whole_s * kNsPerS + round_to_ns(c.second));
}

GpsTime GpsTime::from_utc(const CalendarTime& utc) {
  const GpsTime as_if_gpst = from_calendar_gpst(utc);
  int leap = 0;
  for (const Leap& l : kLeaps) {
    const GpsTime start = from_calendar_gpst({l.year, l.month, l.day, 0, 0, 0.0});
    if (as_if_gpst >= start) leap = l.gps_minus_utc;
  }
  return as_if_gpst.plus_ns(static_cast<int64_t>(leap) * kNsPerS);
}

int gps_minus_utc_s(GpsTime t) {
  int leap = 0;
  for (const Leap& l : kLeaps) {
    // The leap takes effect at UTC midnight = GPST midnight + new offset.
    const GpsTime start = GpsTime::from_calendar_gpst({l.year, l.month, l.day, 0, 0, 0.0}).plus_ns(l.gps_minus_utc * kNsPerS);
    if (t >= start) leap = l.gps_minus_utc;
  }
  return leap;
}

int GpsTime::week() const {
  int64_t w = ns_ / kNsPerWeek;
  if (ns_ % kNsPerWeek < 0) --w;
  return static_cast<int>(w);
}

double GpsTime::tow_s() const {
  int64_t r = ns_ % kNsPerWeek;
  if (r < 0) r += kNsPerWeek;
  return static_cast<double>(r / kNsPerS) + static_cast<double>(r % kNsPerS) * 1e-9;
}

CalendarTime GpsTime::to_calendar_gpst() const { return calendar_from_ns(ns_); }

CalendarTime GpsTime::to_utc() const {
  return calendar_from_ns(ns_ - static_cast<int64_t>(gps_minus_utc_s(*this)) * kNsPerS);
}

std::string GpsTime::to_string() const {
  const CalendarTime c = to_calendar_gpst();
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02d %02d:%02d:%06.3f GPST", c.year, c.month, c.day, c.hour, c.minute,
                std::floor(c.second * 1000.0) / 1000.0);
  return buf;
}

GpsTime GpsTime::plus_s(double dt_s) const { return from_ns(ns_ + round_to_ns(dt_s)); }

}  // namespace pednav
