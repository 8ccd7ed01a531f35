// SPDX-License-Identifier: BSD-2-Clause
// report.html: reading a run folder's files, number formatting, CSV tables (io/report_internal.hpp).
#include "io/report_internal.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

#include "core/geodesy.hpp"
#include "io/trajectory_io.hpp"

namespace pednav::io {

const std::vector<double>* CsvTable::column(const std::string& name) const {
  for (size_t k = 0; k < header.size(); ++k) {
    if (header[k] == name) return &columns[k];
  }
  return nullptr;
}

namespace report_detail {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream ss(line);
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

std::string trim(std::string s) {
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ')) s.pop_back();
  while (!s.empty() && s.front() == ' ') s.erase(s.begin());
  return s;
}

std::string read_text(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '&': o += "&amp;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string num(const nlohmann::json& j, const char* key, const char* f) {
  if (!j.contains(key) || !j[key].is_number()) return "–";
  return fmt::format(fmt::runtime(f), j[key].get<double>());
}

Expected<Solution> load_solution(const fs::path& path, const std::string& name) {
  auto tab = read_csv_table(path.string());
  if (!tab) return tab.error();
  const auto* wk = tab->column("gps_week");
  const auto* tow = tab->column("gps_tow_s");
  const auto* x = tab->column("x_m");
  const auto* y = tab->column("y_m");
  const auto* z = tab->column("z_m");
  const auto* lat = tab->column("lat_deg");
  const auto* lon = tab->column("lon_deg");
  const auto* h = tab->column("h_m");
  if (!wk || !tow || !((x && y && z) || (lat && lon && h))) {
    return make_error(path.string() + ": expected columns gps_week, gps_tow_s and x_m, y_m, z_m (or lat_deg, lon_deg, h_m)");
  }
  Solution s;
  s.name = name;
  for (size_t i = 0; i < tab->rows; ++i) {
    Eigen::Vector3d p;
    if (x && y && z) {
      p = {(*x)[i], (*y)[i], (*z)[i]};
    } else {
      p = ecef_from_geodetic({(*lat)[i] * kDegToRad, (*lon)[i] * kDegToRad, (*h)[i]});
    }
    if (!std::isfinite((*wk)[i]) || !std::isfinite((*tow)[i]) || !p.allFinite()) continue;
    s.t.push_back(GpsTime::from_week_tow(static_cast<int>((*wk)[i]), (*tow)[i]));
    s.p_e.push_back(p);
  }
  s.table = std::move(*tab);
  if (s.t.empty()) return make_error(path.string() + ": no position rows");
  return s;
}

eval::Trajectory trajectory_of(const Solution& s) {
  eval::Trajectory t;
  for (size_t i = 0; i < s.t.size(); ++i) t.points.push_back({s.t[i], s.p_e[i]});
  return t;
}

// The reference named by config.resolved.yaml (path as written, else relative to the run folder).
std::optional<eval::Trajectory> load_reference(const fs::path& dir, std::vector<std::string>& warnings,
                                               std::string& ref_name) {
  const fs::path cfg = dir / "config.resolved.yaml";
  if (!fs::exists(cfg)) return std::nullopt;
  try {
    YAML::Node y = YAML::LoadFile(cfg.string());
    if (!y["reference"] || !y["reference"]["file"]) return std::nullopt;
    fs::path file = y["reference"]["file"].as<std::string>();
    if (!fs::exists(file) && file.is_relative() && fs::exists(dir / file)) file = dir / file;
    TrajectoryReadOptions ro;
    if (y["reference"]["format"]) {
      if (auto f = parse_trajectory_format(y["reference"]["format"].as<std::string>())) ro.format = *f;
    }
    if (y["reference"]["nmea_qualities"]) {
      for (const auto& q : y["reference"]["nmea_qualities"]) ro.nmea_qualities.insert(q.as<int>());
    }
    auto ref = read_trajectory(file.string(), ro);
    if (!ref) {
      warnings.push_back("reference not read: " + ref.error().message);
      return std::nullopt;
    }
    ref_name = file.string();
    return ref->trajectory;
  } catch (const std::exception& e) {
    warnings.push_back(cfg.string() + ": " + e.what());
    return std::nullopt;
  }
}

// A number with the digits that mean something: integers as integers, otherwise three significant digits
// (one decimal at least up to 1e4, none above), no exponent between 1e-3 and 1e7.
std::string pretty_number(double x) {
  if (!std::isfinite(x)) return std::isnan(x) ? "NaN" : (x > 0 ? "inf" : "-inf");
  if (x == std::floor(x) && std::fabs(x) < 1e15) return fmt::format("{:.0f}", x);
  const double a = std::fabs(x);
  if (a >= 1e7 || a < 1e-3) return fmt::format("{:.3g}", x);
  if (a >= 1e4) return fmt::format("{:.0f}", x);
  if (a >= 100) return fmt::format("{:.1f}", x);
  if (a >= 1) return fmt::format("{:.2f}", x);
  return fmt::format("{:.3f}", x);
}

// A JSON value for a person: rounded numbers, lists without quotes, at most 12 items shown.
std::string pretty(const nlohmann::json& v) {
  if (v.is_null()) return "–";
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_integer() || v.is_number_unsigned()) return v.dump();
  if (v.is_number()) return pretty_number(v.get<double>());
  if (v.is_string()) return v.get<std::string>();
  std::string out;
  size_t k = 0;
  constexpr size_t kMaxItems = 12;
  if (v.is_array()) {
    if (v.empty()) return "none";
    for (const auto& e : v) {
      if (k == kMaxItems) {
        out += fmt::format(", … ({} in all)", v.size());
        break;
      }
      out += (k++ ? ", " : "") + pretty(e);
    }
    return v.size() > 1 && !v.front().is_string() ? "[" + out + "]" : out;
  }
  if (v.empty()) return "none";
  for (auto it = v.begin(); it != v.end(); ++it) {
    if (k == kMaxItems) {
      out += fmt::format(", … ({} in all)", v.size());
      break;
    }
    out += (k++ ? ", " : "") + it.key() + ": " + pretty(it.value());
  }
  return out;
}

// summary.json of a run (not of an outage study), or null.
nlohmann::json run_summary(const fs::path& dir, std::vector<std::string>& warnings) {
  if (!fs::exists(dir / "summary.json")) return nullptr;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(read_text(dir / "summary.json"));
  } catch (const std::exception& e) {
    warnings.push_back(std::string("summary.json: ") + e.what());
    return nullptr;
  }
  if (!j.is_object() || (j.contains("windows") && j.contains("keep_sats"))) return nullptr;  // an outage study
  return j;
}

// The value at a dotted path ("gnss.code.used") or null.
const nlohmann::json* at_path(const nlohmann::json& j, const std::string& path) {
  const nlohmann::json* v = &j;
  size_t start = 0;
  while (start <= path.size()) {
    const size_t dot = path.find('.', start);
    const std::string key = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (!v->is_object() || !v->contains(key)) return nullptr;
    v = &(*v)[key];
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return v;
}

long long count_at(const nlohmann::json& j, const std::string& path) {
  const auto* v = at_path(j, path);
  return v && v->is_number() ? v->get<long long>() : -1;
}

// The sum of the counts of a {reason: count} object (accounting's rejected/skipped).
long long sum_counts(const nlohmann::json& j, const std::string& path) {
  const auto* v = at_path(j, path);
  if (!v || !v->is_object()) return -1;
  long long n = 0;
  for (const auto& [k, c] : v->items()) {
    if (c.is_number()) n += c.get<long long>();
  }
  return n;
}

std::string share(long long n, long long of) {
  if (of <= 0) return fmt::format("{}", n);
  return fmt::format("{} of {} ({:.1f} %)", n, of, 100.0 * static_cast<double>(n) / static_cast<double>(of));
}

}  // namespace report_detail

using report_detail::split;
using report_detail::trim;

Expected<CsvTable> read_csv_table(const std::string& path) {
  std::ifstream f(path);
  if (!f) return make_error(path + ": cannot open");
  CsvTable t;
  std::string line;
  if (!std::getline(f, line)) return make_error(path + ":1: expected a header row");
  for (auto& h : split(line)) t.header.push_back(trim(h));
  t.columns.resize(t.header.size());
  int line_no = 1;
  while (std::getline(f, line)) {
    ++line_no;
    if (trim(line).empty()) continue;
    const auto cells = split(line);
    if (cells.size() > t.header.size()) {
      return make_error(fmt::format("{}:{}: {} cells, the header has {} columns", path, line_no, cells.size(),
                                    t.header.size()));
    }
    for (size_t k = 0; k < t.header.size(); ++k) {
      double v = NAN;
      if (k < cells.size()) {
        const std::string c = trim(cells[k]);
        char* end = nullptr;
        if (!c.empty()) {
          v = std::strtod(c.c_str(), &end);
          if (end == c.c_str() || *end != '\0') v = NAN;
        }
      }
      t.columns[k].push_back(v);
    }
    ++t.rows;
  }
  return t;
}

std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const uint32_t v = (static_cast<uint8_t>(bytes[i]) << 16) | (static_cast<uint8_t>(bytes[i + 1]) << 8) |
                       static_cast<uint8_t>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i + 1 == bytes.size()) {
    const uint32_t v = static_cast<uint8_t>(bytes[i]) << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == bytes.size()) {
    const uint32_t v = (static_cast<uint8_t>(bytes[i]) << 16) | (static_cast<uint8_t>(bytes[i + 1]) << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

}  // namespace pednav::io
