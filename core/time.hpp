// SPDX-License-Identifier: BSD-2-Clause
// GPS time: integer nanoseconds since the GPS epoch (1980-01-06 00:00:00 GPST), exposed as week + seconds.
#pragma once

#include <cstdint>
#include <string>

#include "core/expected.hpp"

namespace pednav {

inline constexpr int64_t kNsPerS = 1'000'000'000;
inline constexpr int64_t kSecondsPerWeek = 604'800;
inline constexpr int64_t kNsPerWeek = kSecondsPerWeek * kNsPerS;

/// Calendar date and time of day (UTC or GPST depending on context), seconds may carry a fraction.
struct CalendarTime {
  int year = 1980, month = 1, day = 6, hour = 0, minute = 0;
  double second = 0.0;
};

/// A GPS-time instant with nanosecond resolution; crosses every module boundary.
class GpsTime {
 public:
  constexpr GpsTime() = default;
  /// From nanoseconds since the GPS epoch.
  static constexpr GpsTime from_ns(int64_t ns) { GpsTime t; t.ns_ = ns; return t; }
  /// From GPS week and seconds of week [s] (rounded to the nearest ns).
  static GpsTime from_week_tow(int week, double tow_s);
  /// From seconds since the GPS epoch [s] (rounded to the nearest ns).
  static GpsTime from_seconds(double s);
  /// From a GPST calendar date/time.
  static GpsTime from_calendar_gpst(const CalendarTime& c);
  /// From a UTC calendar date/time using the built-in leap-second table.
  static GpsTime from_utc(const CalendarTime& utc);

  constexpr int64_t ns() const { return ns_; }
  /// GPS week number (continuous, not modulo 1024).
  int week() const;
  /// Seconds of week [s], in [0, 604800).
  double tow_s() const;
  /// Seconds since the GPS epoch [s] (double: ~0.1 us resolution in 2030; use ns() for exact work).
  double seconds() const { return static_cast<double>(ns_) * 1e-9; }
  CalendarTime to_calendar_gpst() const;
  CalendarTime to_utc() const;
  /// "2018-10-04 15:33:40.987 GPST" (milliseconds).
  std::string to_string() const;

  friend constexpr bool operator==(GpsTime a, GpsTime b) { return a.ns_ == b.ns_; }
  friend constexpr auto operator<=>(GpsTime a, GpsTime b) { return a.ns_ <=> b.ns_; }
  /// Difference a - b [s].
  friend double operator-(GpsTime a, GpsTime b) { return static_cast<double>(a.ns_ - b.ns_) * 1e-9; }
  /// Shift by dt_s seconds (rounded to ns).
  GpsTime plus_s(double dt_s) const;
  constexpr GpsTime plus_ns(int64_t dt_ns) const { return from_ns(ns_ + dt_ns); }

 private:
  int64_t ns_ = 0;
};

/// GPS - UTC [s] (leap seconds) valid at the given GPS time (table up to the 2017-01-01 leap second).
int gps_minus_utc_s(GpsTime t);

/// Days since 1970-01-01 of a proleptic Gregorian date.
int64_t days_from_civil(int year, int month, int day);

}  // namespace pednav
