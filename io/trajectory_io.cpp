// SPDX-License-Identifier: BSD-2-Clause
#include "io/trajectory_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>
#include <vector>

#include "core/geodesy.hpp"

namespace pednav::io {
namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\"");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\"");
  return s.substr(b, e - b + 1);
}

std::string_view trim_view(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\"");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\"");
  return s.substr(b, e - b + 1);
}

bool to_double(std::string_view s, double& v) {
  const std::string_view t = trim_view(s);
  if (t.empty()) return false;
  const char* end = t.data() + t.size();
  auto [p, ec] = std::from_chars(t.data(), end, v);
  return ec == std::errc() && p == end && std::isfinite(v);
}

// The cells of one line as views into it (no copy; valid while the line is), reused from line to line.
void split_views(std::string_view s, char sep, std::vector<std::string_view>& out) {
  out.clear();
  size_t start = 0;
  for (;;) {
    size_t end = s.find(sep, start);
    if (end == std::string_view::npos) end = s.size();
    out.push_back(s.substr(start, end - start));
    if (end == s.size()) break;
    start = end + 1;
  }
}

// Append a point, dropping repeated times (counted) and rejecting backwards time with file:line.
Expected<void> push_point(TrajectoryFile& f, const std::string& path, int line, GpsTime t, const Eigen::Vector3d& p,
                          const Eigen::Vector3d& sd_enu_m = Eigen::Vector3d::Constant(std::nan(""))) {
  auto& pts = f.trajectory.points;
  if (!pts.empty()) {
    if (t == pts.back().t) {
      ++f.skipped_duplicate_time;
      return {};
    }
    if (t < pts.back().t) {
      return make_error(fmt::format("{}:{}: time {} is before the previous {}", path, line, t.to_string(),
                                    pts.back().t.to_string()));
    }
  }
  pts.push_back({t, p, sd_enu_m});
  return {};
}

// Time fields a GpsTime can hold without overflow and a receiver can produce (fuzzing found a year of 2e3 giving a
// signed overflow in the nanosecond count): GPS weeks 0..9999, calendar years 1980..2199.
constexpr int kMaxGpsWeek = 9999;
bool valid_week_tow(double week, double tow_s) {
  return week >= 0 && week <= kMaxGpsWeek && week == std::floor(week) && tow_s >= -604800.0 && tow_s <= 2 * 604800.0;
}
bool valid_calendar(const CalendarTime& c) {
  return c.year >= 1980 && c.year < 2200 && c.month >= 1 && c.month <= 12 && c.day >= 1 && c.day <= 31 && c.hour >= 0 &&
         c.hour <= 24 && c.minute >= 0 && c.minute <= 59 && c.second >= 0.0 && c.second < 61.0;
}

bool nmea_checksum_ok(const std::string& s) {
  const auto star = s.find('*');
  if (s.empty() || s[0] != '$' || star == std::string::npos || star + 3 > s.size()) return false;
  unsigned x = 0;
  for (size_t i = 1; i < star; ++i) x ^= static_cast<unsigned char>(s[i]);
  unsigned given = 0;
  return std::sscanf(s.c_str() + star + 1, "%2x", &given) == 1 && given == x;
}

// ddmm.mmmm + hemisphere -> radians
bool nmea_angle(const std::string& v, const std::string& hemi, int deg_digits, double& rad) {
  double x = 0.0;
  if (v.size() < static_cast<size_t>(deg_digits) + 2 || !to_double(v, x)) return false;
  const double deg = std::floor(x / 100.0);
  const double minutes = x - deg * 100.0;
  double d = deg + minutes / 60.0;
  if (hemi == "S" || hemi == "W") d = -d;
  else if (hemi != "N" && hemi != "E") return false;
  rad = d * kDegToRad;
  return true;
}

}  // namespace

Expected<TrajectoryFormat> parse_trajectory_format(const std::string& name) {
  if (name == "auto") return TrajectoryFormat::kAuto;
  if (name == "csv") return TrajectoryFormat::kCsv;
  if (name == "pos") return TrajectoryFormat::kPos;
  if (name == "nmea") return TrajectoryFormat::kNmea;
  return make_error("unknown trajectory format '" + name + "' (expected auto, csv, pos or nmea)");
}

Expected<TrajectoryFile> read_nmea_gga(const std::string& path, const TrajectoryReadOptions& options) {
  std::ifstream in(path);
  if (!in) return make_error(path + ": cannot open file");
  TrajectoryFile f;
  f.format = "nmea";
  // UTC date: from RMC (field 9, ddmmyy) or the option; advances when the GGA time of day wraps.
  int year = 0, month = 0, day = 0;
  if (!options.nmea_date.empty() && (std::sscanf(options.nmea_date.c_str(), "%d-%d-%d", &year, &month, &day) != 3 ||
                                      !valid_calendar({year, month, day, 0, 0, 0.0}))) {
    return make_error("nmea date '" + options.nmea_date + "': expected YYYY-MM-DD");
  }
  double last_sod = -1.0;
  std::string line;
  int n = 0;
  bool any_gga = false;
  while (std::getline(in, line)) {
    ++n;
    ++f.lines;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() < 7 || line[0] != '$') continue;
    const std::string type = line.substr(3, 3);
    if (type != "GGA" && type != "RMC") continue;
    if (!nmea_checksum_ok(line)) {
      ++f.skipped_checksum;
      continue;
    }
    const auto fields = split(line.substr(0, line.find('*')), ',');
    if (type == "RMC") {
      // The first RMC date is the session's UTC date; later days follow from the GGA time-of-day wrap.
      if (year == 0 && fields.size() > 9 && fields[9].size() == 6) {
        int d = 0, m = 0, y = 0;
        if (std::sscanf(fields[9].c_str(), "%2d%2d%2d", &d, &m, &y) == 3 && valid_calendar({2000 + y, m, d, 0, 0, 0.0})) {
          year = 2000 + y;
          month = m;
          day = d;
        }
      }
      continue;
    }
    any_gga = true;
    if (fields.size() < 12) return make_error(fmt::format("{}:{}: GGA sentence has {} fields, expected 15", path, n, fields.size()));
    int quality = 0;
    if (fields[6].empty() || std::from_chars(fields[6].data(), fields[6].data() + fields[6].size(), quality).ec != std::errc()) {
      return make_error(fmt::format("{}:{}: GGA fix quality '{}' is not a number", path, n, fields[6]));
    }
    if (quality < 1 || (!options.nmea_qualities.empty() && !options.nmea_qualities.count(quality))) {
      ++f.skipped_quality;
      continue;
    }
    double hhmmss = 0.0, alt = 0.0, sep = 0.0;
    Geodetic g;
    if (!to_double(fields[1], hhmmss) || !nmea_angle(fields[2], fields[3], 2, g.lat) ||
        !nmea_angle(fields[4], fields[5], 3, g.lon) || !to_double(fields[9], alt)) {
      ++f.skipped_empty;
      continue;
    }
    if (!fields[11].empty() && !to_double(fields[11], sep)) {
      return make_error(fmt::format("{}:{}: GGA geoid separation '{}' is not a number", path, n, fields[11]));
    }
    if (year == 0) {
      return make_error(fmt::format("{}:{}: GGA has no date and no RMC came before it; give the UTC date (--nmea-date YYYY-MM-DD)", path, n));
    }
    const double hh = std::floor(hhmmss / 10000.0), mm = std::floor((hhmmss - hh * 10000.0) / 100.0);
    const double ss = hhmmss - hh * 10000.0 - mm * 100.0;
    if (!(hhmmss >= 0.0) || hh > 23 || mm > 59 || ss >= 61.0) {
      return make_error(fmt::format("{}:{}: GGA time '{}' is not hhmmss.ss", path, n, fields[1]));
    }
    const double sod = hh * 3600.0 + mm * 60.0 + ss;
    CalendarTime c{year, month, day, 0, 0, 0.0};
    GpsTime midnight = GpsTime::from_utc(c);
    if (last_sod >= 0.0 && sod + 43200.0 < last_sod) {  // wrapped past UTC midnight
      midnight = midnight.plus_s(86400.0);
      const CalendarTime next = midnight.to_utc();
      year = next.year;
      month = next.month;
      day = next.day;
    }
    last_sod = sod;
    g.h_m = alt + sep;  // MSL altitude + geoid separation = ellipsoidal height
    if (auto ok = push_point(f, path, n, midnight.plus_s(sod), ecef_from_geodetic(g)); !ok) return ok.error();
  }
  if (!any_gga) return make_error(path + ": no GGA sentence found (is this an NMEA file?)");
  if (f.trajectory.points.empty()) {
    return make_error(fmt::format("{}: no GGA fix kept ({} with another quality, {} bad checksums)", path,
                                  f.skipped_quality, f.skipped_checksum));
  }
  return f;
}

Expected<TrajectoryFile> read_rtklib_pos(const std::string& path) {
  std::ifstream in(path);
  if (!in) return make_error(path + ": cannot open file");
  TrajectoryFile f;
  f.format = "pos";
  bool ecef = false, utc = false, seen_header = false;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    ++f.lines;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line[0] == '%') {
      if (line.find("x-ecef") != std::string::npos) ecef = true;
      if (line.find("latitude") != std::string::npos || line.find("x-ecef") != std::string::npos) {
        seen_header = true;
        utc = line.find("UTC") != std::string::npos;
      }
      continue;
    }
    std::istringstream is(line);
    std::string a, b;
    is >> a >> b;
    GpsTime t;
    if (a.find('/') != std::string::npos) {
      CalendarTime c;
      if (std::sscanf(a.c_str(), "%d/%d/%d", &c.year, &c.month, &c.day) != 3 ||
          std::sscanf(b.c_str(), "%d:%d:%lf", &c.hour, &c.minute, &c.second) != 3 || !valid_calendar(c)) {
        return make_error(fmt::format("{}:{}: expected 'YYYY/MM/DD HH:MM:SS.SSS' time, got '{} {}'", path, n, a, b));
      }
      t = utc ? GpsTime::from_utc(c) : GpsTime::from_calendar_gpst(c);
    } else {
      double week = 0, tow = 0;
      if (!to_double(a, week) || !to_double(b, tow) || !valid_week_tow(week, tow)) {
        return make_error(fmt::format("{}:{}: expected 'week tow' or a calendar time, got '{} {}'", path, n, a, b));
      }
      t = GpsTime::from_week_tow(static_cast<int>(week), tow);
    }
    double v[3];
    std::string tok;
    for (double& x : v) {
      if (!(is >> tok) || !to_double(tok, x)) {
        return make_error(fmt::format("{}:{}: expected three position numbers after the time", path, n));
      }
    }
    const Eigen::Vector3d p = ecef ? Eigen::Vector3d(v[0], v[1], v[2])
                                   : ecef_from_geodetic({v[0] * kDegToRad, v[1] * kDegToRad, v[2]});
    if (auto ok = push_point(f, path, n, t, p); !ok) return ok.error();
  }
  if (!seen_header && f.trajectory.points.empty()) return make_error(path + ": not an RTKLIB .pos file (no header, no data)");
  if (f.trajectory.points.empty()) return make_error(path + ": no solution epochs");
  return f;
}

Expected<TrajectoryFile> read_trajectory_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) return make_error(path + ": cannot open file");
  TrajectoryFile f;
  f.format = "csv";
  std::string line;
  if (!std::getline(in, line)) return make_error(path + ": file is empty");
  ++f.lines;
  const auto header = split(line, ',');
  std::map<std::string, int> col;
  for (size_t i = 0; i < header.size(); ++i) col[trim(header[i])] = static_cast<int>(i);
  auto find = [&](std::initializer_list<const char*> names) -> int {
    for (const char* nm : names) {
      auto it = col.find(nm);
      if (it != col.end()) return it->second;
    }
    return -1;
  };
  const int c_week = find({"gps_week"}), c_tow = find({"gps_tow_s"});
  const int c_week1024 = find({"GpsWeek"}), c_cycle = find({"GpsCycle"}), c_tow2 = find({"GpsToW [s]"});
  if (!((c_week >= 0 && c_tow >= 0) || (c_week1024 >= 0 && c_cycle >= 0 && c_tow2 >= 0))) {
    return make_error(path + ":1: header lacks time columns (expected gps_week, gps_tow_s)");
  }
  int pc[3] = {-1, -1, -1};
  int kind = -1;  // 0 geodetic, 1 ecef, 2 local
  const std::initializer_list<const char*> names[3][3] = {
      {{"lat_deg"}, {"lon_deg"}, {"h_m"}},
      {{"x_m", "Pos ECEF X [m]"}, {"y_m", "Pos ECEF Y [m]"}, {"z_m", "Pos ECEF Z [m]"}},
      {{"e_m"}, {"n_m"}, {"u_m"}}};
  for (int k = 0; k < 3 && kind < 0; ++k) {
    int found = 0;
    for (int j = 0; j < 3; ++j) {
      pc[j] = find(names[k][j]);
      found += pc[j] >= 0;
    }
    if (found == 3) kind = k;
  }
  if (kind < 0) {
    return make_error(path + ":1: header lacks position columns (expected lat_deg, lon_deg, h_m or x_m, y_m, z_m or e_m, n_m, u_m)");
  }
  f.trajectory.frame = kind == 2 ? eval::Frame::kLocalEnu : eval::Frame::kEcef;
  // The solution's own σ (pednav solution.csv / smoothed.csv): optional, empty cells = unknown.
  const int c_sd[3] = {find({"sd_e_m"}), find({"sd_n_m"}), find({"sd_d_m"})};
  int n = 1;
  std::vector<std::string_view> cells;
  while (std::getline(in, line)) {
    ++n;
    ++f.lines;
    if (trim_view(line).empty()) continue;
    split_views(line, ',', cells);
    auto cell = [&](int c) -> std::string_view {
      return c >= 0 && c < static_cast<int>(cells.size()) ? cells[c] : std::string_view();
    };
    double week = 0, tow = 0;
    if (c_week >= 0 && c_tow >= 0) {
      if (!to_double(cell(c_week), week) || !to_double(cell(c_tow), tow)) {
        return make_error(fmt::format("{}:{}: expected numbers in gps_week, gps_tow_s", path, n));
      }
    } else {
      double w1024 = 0, cycle = 0;
      if (!to_double(cell(c_week1024), w1024) || !to_double(cell(c_cycle), cycle) || !to_double(cell(c_tow2), tow)) {
        return make_error(fmt::format("{}:{}: expected numbers in GpsCycle, GpsWeek, GpsToW [s]", path, n));
      }
      week = cycle * 1024 + w1024;
    }
    if (!valid_week_tow(week, tow)) {
      return make_error(fmt::format("{}:{}: time (GPS week {}, {} s) is out of range (weeks 0..{})", path, n, week, tow, kMaxGpsWeek));
    }
    double v[3];
    bool ok = true;
    int empty = 0;
    for (int j = 0; j < 3; ++j) {
      if (trim_view(cell(pc[j])).empty()) ++empty;
      else ok = ok && to_double(cell(pc[j]), v[j]);
    }
    if (empty == 3) {
      ++f.skipped_empty;
      continue;
    }
    if (!ok || empty > 0) return make_error(fmt::format("{}:{}: expected 3 numbers in the position columns", path, n));
    Eigen::Vector3d p;
    if (kind == 0) p = ecef_from_geodetic({v[0] * kDegToRad, v[1] * kDegToRad, v[2]});
    else p = Eigen::Vector3d(v[0], v[1], v[2]);
    Eigen::Vector3d sd = Eigen::Vector3d::Constant(std::nan(""));
    for (int j = 0; j < 3; ++j) {
      double x = 0.0;
      if (c_sd[j] >= 0 && !trim_view(cell(c_sd[j])).empty() && to_double(cell(c_sd[j]), x) && std::isfinite(x) && x >= 0.0) sd(j) = x;
    }
    if (auto r = push_point(f, path, n, GpsTime::from_week_tow(static_cast<int>(week), tow), p, sd); !r) return r.error();
  }
  if (f.trajectory.points.empty()) return make_error(path + ": no rows with a position");
  return f;
}

Expected<TrajectoryFile> read_trajectory(const std::string& path, const TrajectoryReadOptions& options) {
  TrajectoryFormat fmt_ = options.format;
  if (fmt_ == TrajectoryFormat::kAuto) {
    std::ifstream in(path);
    if (!in) return make_error(path + ": cannot open file");
    std::string first;
    std::getline(in, first);
    if (first.empty() && in.eof()) return make_error(path + ": file is empty");
    const auto dot = path.rfind('.');
    const std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
    if (first.rfind("$", 0) == 0 || ext == "nmea" || ext == "gga") fmt_ = TrajectoryFormat::kNmea;
    else if (first.rfind("%", 0) == 0 || ext == "pos") fmt_ = TrajectoryFormat::kPos;
    else fmt_ = TrajectoryFormat::kCsv;
  }
  switch (fmt_) {
    case TrajectoryFormat::kNmea: return read_nmea_gga(path, options);
    case TrajectoryFormat::kPos: return read_rtklib_pos(path);
    default: return read_trajectory_csv(path);
  }
}

}  // namespace pednav::io
