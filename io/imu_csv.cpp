// SPDX-License-Identifier: BSD-2-Clause
// IMU CSV reader: one pass over the bytes with std::from_chars (no iostreams per field), then the checks.
#include "io/imu_csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/geodesy.hpp"

namespace pednav::io {
namespace {

constexpr double kG0 = 9.80665;
constexpr double kGpsMinusUnixEpoch_s = 315964800.0;  // 1980-01-06 - 1970-01-01 (no leap seconds: GPST scale)
// Largest |GPST| of a sample [ns]: 4e18 ns = 126 years after 1980; differences of two such times fit in int64.
constexpr double kMaxAbsTime_ns = 4e18;

std::string num(double v, const char* f = "%.6g") {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

bool parse_field(const char* b, const char* e, double& out) {
  while (b < e && (*b == ' ' || *b == '\t' || *b == '"')) ++b;
  while (e > b && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '"')) --e;
  if (b == e) return false;
  if (*b == '+') ++b;
  const auto r = std::from_chars(b, e, out);
  return r.ec == std::errc() && r.ptr == e && std::isfinite(out);
}

double gyro_scale(const std::string& u) { return (u == "deg_per_s" || u == "deg") ? kDegToRad : 1.0; }
double accel_scale(const std::string& u) { return u == "g" ? kG0 : 1.0; }
bool gyro_is_increment(const std::string& u) { return u == "rad" || u == "deg"; }
bool accel_is_increment(const std::string& u) { return u == "mps"; }

// | |f_rest| - 9.8 | above which a log that passes the unit check still gets a warning [m/s^2] (~2σ of a
// Crista-class accelerometer's turn-on bias and scale error).
constexpr double kRestWarning_mps2 = 0.6;

// Which accelerometer unit setting would make the rest |f| equal to g.
std::string accel_unit_hint(double f_rest, const ImuFormat& fmt) {
  if (std::abs(f_rest - 1.0) < 0.1 && fmt.accel_unit != "g") return "accel.unit is probably g (|f| at rest is about 1)";
  if (std::abs(f_rest - kG0 * kG0) < 6.0 && fmt.accel_unit == "g")
    return "accel.unit is probably mps2, not g (|f| at rest is about 96)";
  if (f_rest < 0.2 * kG0) return "the accelerometer columns may hold increments (accel.unit: mps) or the wrong columns";
  return "check accel.unit (" + fmt.accel_unit + ") and accel.columns";
}

}  // namespace

std::vector<std::string> ImuFormat::problems() const {
  std::vector<std::string> p;
  if (time_base != "gps_sow" && time_base != "gpst_unix" && time_base != "relative" && time_base != "index")
    p.push_back("time.base: expected one of {gps_sow, gpst_unix, relative, index}, got '" + time_base + "'");
  if (time_base == "gps_sow" && gps_week < 0) p.push_back("time.gps_week: required for time.base gps_sow");
  if (time_base == "index" && !(index_rate_hz > 0.0)) p.push_back("time.rate_hz: required (> 0) for time.base index");
  if (gyro_unit != "rad_per_s" && gyro_unit != "deg_per_s" && gyro_unit != "rad" && gyro_unit != "deg")
    p.push_back("gyro.unit: expected one of {rad_per_s, deg_per_s, rad, deg}, got '" + gyro_unit + "'");
  if (accel_unit != "mps2" && accel_unit != "g" && accel_unit != "mps")
    p.push_back("accel.unit: expected one of {mps2, g, mps}, got '" + accel_unit + "'");
  for (int c : gyro_columns)
    if (c < 0) p.push_back("gyro.columns: column indices are 0-based and >= 0");
  for (int c : accel_columns)
    if (c < 0) p.push_back("accel.columns: column indices are 0-based and >= 0");
  for (int i = 0; i < 3; ++i) {
    if (std::abs(std::abs(gyro_signs(i)) - 1.0) > 0 || std::abs(std::abs(accel_signs(i)) - 1.0) > 0) {
      p.push_back("signs: each sign must be 1 or -1");
      break;
    }
  }
  if (stance_column < -1) p.push_back("stance.column: column indices are 0-based and >= 0");
  if (mag_columns[0] >= 0) {
    for (int c : mag_columns)
      if (c < 0) p.push_back("mag.columns: column indices are 0-based and >= 0");
    if (!(mag_scale_to_ut > 0.0)) p.push_back("mag.unit: scale must be > 0");
  }
  if (!(max_gap_s > 0.0)) p.push_back("max_gap_s must be > 0");
  if (header_lines < 0) p.push_back("header_lines must be >= 0");
  return p;
}

Expected<ImuLog> parse_imu_csv(const char* data, size_t size, const std::string& name, const ImuFormat& fmt) {
  if (const auto pr = fmt.problems(); !pr.empty()) {
    std::string m = name + ": invalid IMU format '" + fmt.name + "':";
    for (const auto& s : pr) m += " " + s + ";";
    return make_error(m);
  }
  const bool use_time = fmt.time_base != "index";
  const bool base_gps_sow = fmt.time_base == "gps_sow", base_gpst_unix = fmt.time_base == "gpst_unix";
  // Column -> slot (0 time, 1-3 gyro, 4-6 accel).
  int max_col = use_time ? fmt.time_column : 0;
  for (int c : fmt.gyro_columns) max_col = std::max(max_col, c);
  for (int c : fmt.accel_columns) max_col = std::max(max_col, c);
  const bool labels = fmt.stance_column >= 0;
  if (labels) max_col = std::max(max_col, fmt.stance_column);
  const bool mag = fmt.mag_columns[0] >= 0;
  if (mag) {
    for (int c : fmt.mag_columns) max_col = std::max(max_col, c);
  }
  std::vector<signed char> slot(max_col + 1, -1);
  if (labels) slot[fmt.stance_column] = 7;
  if (mag) {
    for (int i = 0; i < 3; ++i) slot[fmt.mag_columns[i]] = static_cast<signed char>(8 + i);
  }
  if (use_time) slot[fmt.time_column] = 0;
  for (int i = 0; i < 3; ++i) {
    slot[fmt.gyro_columns[i]] = static_cast<signed char>(1 + i);
    slot[fmt.accel_columns[i]] = static_cast<signed char>(4 + i);
  }
  const double gs = gyro_scale(fmt.gyro_unit), as = accel_scale(fmt.accel_unit);
  const double start_ns = fmt.start_epoch ? static_cast<double>(fmt.start_epoch->ns()) : 0.0;

  ImuLog log;
  ImuLogReport& rep = log.report;
  log.samples.reserve(size / 48 + 16);
  std::vector<long> lines;
  lines.reserve(size / 48 + 16);
  Eigen::Vector3d last_gyro = Eigen::Vector3d::Zero(), last_acc = Eigen::Vector3d::Zero();  // sensor-frame values of
                                                                                             // the last sample kept
                                                                                             // (duplicate comparison)
  const char* p = data;
  const char* const end = data + size;
  long line = 0;
  std::string first_bad_reason;
  long data_index = 0;
  double vals[11];
  while (p < end) {
    const char* le = static_cast<const char*>(std::memchr(p, '\n', static_cast<size_t>(end - p)));
    if (!le) le = end;
    const char* next = le < end ? le + 1 : end;
    const char* lend = (le > p && le[-1] == '\r') ? le - 1 : le;
    ++line;
    if (line <= fmt.header_lines || lend == p) {
      p = next;
      continue;
    }
    ++rep.rows;
    if (le == end) {  // the file ends inside this line: "0.0123" may be the start of "0.012345" (truncation)
      ++rep.truncated_rows;
      break;
    }
    // Split and parse the needed columns.
    const char* f = p;
    bool ok = true;
    int col = 0;
    for (; col <= max_col; ++col) {
      const char* fe = static_cast<const char*>(std::memchr(f, fmt.delimiter, static_cast<size_t>(lend - f)));
      if (!fe) fe = lend;
      if (slot[col] >= 0 && !parse_field(f, fe, vals[slot[col]])) {
        ok = false;
        if (first_bad_reason.empty())
          first_bad_reason = "column " + std::to_string(col) + " is '" + std::string(f, fe) + "' (expected a finite number)";
        break;
      }
      if (fe == lend) {
        ++col;
        break;
      }
      f = fe + 1;
    }
    if (ok && col <= max_col) {
      ok = false;
      if (first_bad_reason.empty())
        first_bad_reason = "only " + std::to_string(col) + " columns (expected at least " + std::to_string(max_col + 1) + ")";
    }
    if (ok && labels && vals[7] != 0.0 && vals[7] != 1.0) {
      ok = false;
      if (first_bad_reason.empty())
        first_bad_reason = "stance column " + std::to_string(fmt.stance_column) + " is '" + num(vals[7]) +
                           "' (expected 0 or 1)";
    }
    const long index = data_index++;
    if (!ok) {
      ++rep.bad_rows;
      if (!rep.first_bad_line) rep.first_bad_line = line;
      p = next;
      continue;
    }
    double t_s = use_time ? vals[0] * fmt.time_scale_s : static_cast<double>(index) / fmt.index_rate_hz;
    double t_ns = 0.0;  // GPST nanoseconds, in double first: a garbage time stamp must not overflow the integer count
    if (base_gps_sow) {
      t_ns = static_cast<double>(fmt.gps_week) * static_cast<double>(kNsPerWeek) + t_s * 1e9;
    } else if (base_gpst_unix) {
      t_ns = (t_s - kGpsMinusUnixEpoch_s) * 1e9;
    } else {
      t_ns = start_ns + t_s * 1e9;
    }
    if (!(std::abs(t_ns) < kMaxAbsTime_ns)) {
      ++rep.bad_rows;
      if (!rep.first_bad_line) rep.first_bad_line = line;
      if (first_bad_reason.empty()) first_bad_reason = "time " + num(t_s) + " s is out of range";
      p = next;
      continue;
    }
    // Range checked in double; the time itself in integer nanoseconds (a double holds 1.4e18 ns only to 256 ns,
    // which jitters the sample intervals: test NoiseFreeWalk caught it).
    GpsTime t;
    if (base_gps_sow) {
      t = GpsTime::from_ns(static_cast<int64_t>(fmt.gps_week) * kNsPerWeek + std::llround(t_s * 1e9));
    } else if (base_gpst_unix) {
      t = GpsTime::from_ns(std::llround((t_s - kGpsMinusUnixEpoch_s) * 1e9));
    } else {
      t = GpsTime::from_ns(std::llround(start_ns + t_s * 1e9));
    }
    const Eigen::Vector3d g_s(vals[1] * gs * fmt.gyro_signs(0), vals[2] * gs * fmt.gyro_signs(1),
                              vals[3] * gs * fmt.gyro_signs(2));
    const Eigen::Vector3d a_s(vals[4] * as * fmt.accel_signs(0), vals[5] * as * fmt.accel_signs(1),
                              vals[6] * as * fmt.accel_signs(2));
    if (!log.samples.empty()) {
      const GpsTime prev = log.samples.back().t;
      if (t < prev) {
        return make_error(name + ":" + std::to_string(line) + ": time " + num(t_s, "%.6f") + " s is not after the previous " +
                          num(t_s - (t - prev), "%.6f") + " s (line " + std::to_string(lines.back()) + ")");
      }
      if (t == prev) {
        ++rep.duplicates_dropped;
        if (g_s != last_gyro || a_s != last_acc) ++rep.duplicates_differing;
        p = next;
        continue;
      }
    }
    ins::ImuSample s;
    s.t = t;
    s.omega_ib_b = g_s;  // mounting applied after increment conversion
    s.f_ib_b = a_s;
    log.samples.push_back(s);
    if (labels) log.stance.push_back(vals[7] != 0.0 ? 1 : 0);
    if (mag) {
      log.mag_b.push_back(fmt.R_b_s * Eigen::Vector3d(vals[8] * fmt.mag_signs(0), vals[9] * fmt.mag_signs(1),
                                                     vals[10] * fmt.mag_signs(2)) *
                          fmt.mag_scale_to_ut);
    }
    last_gyro = g_s;
    last_acc = a_s;
    lines.push_back(line);
    p = next;
  }
  const long n = static_cast<long>(log.samples.size());
  rep.samples = n;
  if (n < 2) return make_error(name + ": " + std::to_string(n) + " usable IMU samples (need at least 2)" +
                               (rep.first_bad_line ? "; first bad row at line " + std::to_string(rep.first_bad_line) + ": " + first_bad_reason : ""));
  // Time steps, median, gaps.
  std::vector<double> dts(n - 1);
  for (long i = 1; i < n; ++i) dts[i - 1] = log.samples[i].t - log.samples[i - 1].t;
  {
    std::vector<double> tmp = dts;
    std::nth_element(tmp.begin(), tmp.begin() + tmp.size() / 2, tmp.end());
    rep.median_dt_s = tmp[tmp.size() / 2];
  }
  rep.rate_hz = 1.0 / rep.median_dt_s;
  rep.duration_s = log.samples.back().t - log.samples.front().t;
  for (long i = 1; i < n; ++i) {
    const double dt = dts[i - 1];
    if (dt > fmt.gap_factor * rep.median_dt_s) {
      ++rep.gaps;
      if (dt > rep.longest_gap_s) {
        rep.longest_gap_s = dt;
        rep.longest_gap_line = lines[i];
      }
    }
    if (dt > fmt.max_gap_s) {
      return make_error(name + ":" + std::to_string(lines[i]) + ": gap of " + num(dt, "%.4f") +
                        " s exceeds the bridging limit max_gap_s = " + num(fmt.max_gap_s) + " s");
    }
  }
  // Increments -> rates (the increment of row k is taken over (t_{k-1}, t_k]).
  const bool gi = gyro_is_increment(fmt.gyro_unit), ai = accel_is_increment(fmt.accel_unit);
  for (long i = 0; i < n; ++i) {
    const double dt = i > 0 ? dts[i - 1] : dts[0];
    auto& s = log.samples[i];
    if (gi) s.omega_ib_b /= dt;
    if (ai) s.f_ib_b /= dt;
    // Saturation on the sensor axes (after unit conversion, before mounting).
    const double wmax = s.omega_ib_b.cwiseAbs().maxCoeff(), fmax = s.f_ib_b.cwiseAbs().maxCoeff();
    if ((fmt.gyro_full_scale > 0 && wmax >= 0.999 * fmt.gyro_full_scale) ||
        (fmt.accel_full_scale > 0 && fmax >= 0.999 * fmt.accel_full_scale))
      ++rep.saturated_samples;
    if ((fmt.gyro_full_scale > 0 && wmax > 1.01 * fmt.gyro_full_scale) ||
        (fmt.accel_full_scale > 0 && fmax > 1.01 * fmt.accel_full_scale))
      ++rep.above_full_scale;
    s.omega_ib_b = fmt.R_b_s * s.omega_ib_b;
    s.f_ib_b = fmt.R_b_s * s.f_ib_b;
    rep.max_gyro_norm_radps = std::max(rep.max_gyro_norm_radps, s.omega_ib_b.norm());
    rep.max_accel_norm_mps2 = std::max(rep.max_accel_norm_mps2, s.f_ib_b.norm());
  }
  // Stillest 0.5 s window (smallest summed gyro variance): its mean |f| is the rest specific force.
  const long w = std::min<long>(n, std::max<long>(2, std::lround(0.5 * rep.rate_hz)));
  double best = 1e300;
  for (long b = 0; b + w <= n; b += w / 2 > 0 ? w / 2 : 1) {
    Eigen::Vector3d m = Eigen::Vector3d::Zero(), m2 = Eigen::Vector3d::Zero(), mf = Eigen::Vector3d::Zero();
    for (long i = b; i < b + w; ++i) {
      m += log.samples[i].omega_ib_b;
      m2 += log.samples[i].omega_ib_b.cwiseAbs2();
      mf += log.samples[i].f_ib_b;
    }
    const double var = (m2 / w - (m / w).cwiseAbs2()).sum();
    if (var < best) {
      best = var;
      rep.rest_f_norm_mps2 = (mf / w).norm();
      rep.rest_window_start_s = log.samples[b].t - log.samples.front().t;
    }
  }
  // Unit checks.
  if (std::abs(rep.rest_f_norm_mps2 - kG0) > fmt.rest_tolerance_mps2) {
    return make_error(name + ": specific force at rest is " + num(rep.rest_f_norm_mps2, "%.4g") +
                      " m/s^2 after conversion (expected about 9.8; stillest window at " +
                      num(rep.rest_window_start_s, "%.2f") + " s): " + accel_unit_hint(rep.rest_f_norm_mps2, fmt));
  }
  if (fmt.gyro_unit == "rad_per_s" && rep.max_gyro_norm_radps > 40.0) {
    return make_error(name + ": angular rate reaches " + num(rep.max_gyro_norm_radps, "%.4g") +
                      " rad/s, beyond any foot IMU: gyro.unit is probably deg_per_s, not rad_per_s");
  }
  if (const double dev = std::abs(rep.rest_f_norm_mps2 - kG0); dev > kRestWarning_mps2) {
    rep.warnings.push_back("specific force at rest is " + num(rep.rest_f_norm_mps2, "%.4g") + " m/s^2 (" +
                           num(dev, "%.2f") + " from 9.81; stillest window at " +
                           num(rep.rest_window_start_s, "%.2f") +
                           " s): a large accelerometer bias or scale-factor error, or accel.unit/columns are wrong");
  }
  if (rep.truncated_rows)
    rep.warnings.push_back("the last line (" + name + ":" + std::to_string(line) +
                           ") has no line end: the file was cut off; that row was dropped");
  if (rep.duplicates_dropped)
    rep.warnings.push_back(std::to_string(rep.duplicates_dropped) + " duplicate time stamps dropped (" +
                           std::to_string(rep.duplicates_differing) + " with differing values)");
  if (rep.bad_rows)
    rep.warnings.push_back(std::to_string(rep.bad_rows) + " rows with NaN/empty/unparsable fields dropped; first at " +
                           name + ":" + std::to_string(rep.first_bad_line) + ": " + first_bad_reason);
  if (rep.above_full_scale)
    rep.warnings.push_back(std::to_string(rep.above_full_scale) +
                           " samples exceed the configured full scale by > 1 %: the full_scale setting is probably "
                           "lower than the device's range");
  else if (rep.saturated_samples)
    rep.warnings.push_back(std::to_string(rep.saturated_samples) + " samples at >= 99.9 % of the configured full scale (saturated)");
  if (rep.gaps)
    rep.warnings.push_back(std::to_string(rep.gaps) + " gaps (> " + num(fmt.gap_factor) + " x median step), longest " +
                           num(rep.longest_gap_s, "%.4f") + " s at " + name + ":" + std::to_string(rep.longest_gap_line) +
                           ", bridged");
  return log;
}

Expected<ImuLog> read_imu_csv(const std::string& path, const ImuFormat& format) {
  // A regular file is mapped read-only: no copy into a zero-filled buffer (on a 50 MB log that copy and its page
  // faults were a third of an INS/ZUPT run). Anything else (a pipe, a special file) is read into memory.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return make_error(path + ": cannot open IMU log");
  struct stat st {};
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
    const auto size = static_cast<size_t>(st.st_size);
    void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    ::close(fd);
    if (map != MAP_FAILED) {
      ::madvise(map, size, MADV_SEQUENTIAL);
      auto log = parse_imu_csv(static_cast<const char*>(map), size, path, format);
      ::munmap(map, size);
      return log;
    }
  } else {
    ::close(fd);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(path + ": cannot open IMU log");
  std::string buf{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  return parse_imu_csv(buf.data(), buf.size(), path, format);
}

}  // namespace pednav::io
