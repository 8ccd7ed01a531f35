// SPDX-License-Identifier: BSD-2-Clause
#include "io/report.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <array>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/geodesy.hpp"
#include "eval/statistics.hpp"
#include "eval/trajectory.hpp"
#include "io/atomic_file.hpp"
#include "io/plot.hpp"
#include "io/plot_figures.hpp"
#include "io/trajectory_io.hpp"

namespace pednav::io {
namespace fs = std::filesystem;

const std::vector<double>* CsvTable::column(const std::string& name) const {
  for (size_t k = 0; k < header.size(); ++k) {
    if (header[k] == name) return &columns[k];
  }
  return nullptr;
}

namespace {

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

std::string num(const nlohmann::json& j, const char* key, const char* f = "{:.2f}") {
  if (!j.contains(key) || !j[key].is_number()) return "–";
  return fmt::format(fmt::runtime(f), j[key].get<double>());
}

// A solution file as time + ECEF + optional sigma/satellite/ZUPT columns.
struct Solution {
  std::string name;
  std::vector<GpsTime> t;
  std::vector<Eigen::Vector3d> p_e;
  CsvTable table;
};

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

class Html {
 public:
  std::string body;
  int plots = 0;
  std::vector<std::string> sections;
  std::vector<std::string>& warnings;
  explicit Html(std::vector<std::string>& w) : warnings(w) {}
  void section(const std::string& title) {
    sections.push_back(title);
    body += "<h2>" + esc(title) + "</h2>\n";
  }
  void para(const std::string& text) { body += "<p>" + esc(text) + "</p>\n"; }
  void row_open() { body += "<div class=\"row\">\n"; }  // plots side by side while the page is wide enough
  void row_close() { body += "</div>\n"; }
  void plot(const PlotSpec& spec, const std::string& caption) {
    auto svg = render_svg(spec);
    if (!svg) {
      warnings.push_back(svg.error().message);
      body += "<p class=\"warn\">plot not rendered: " + esc(svg.error().message) + "</p>\n";
      return;
    }
    ++plots;
    body += "<figure><img class=\"plot\" alt=\"" + esc(spec.title) + "\" src=\"data:image/svg+xml;base64," +
            base64(*svg) + "\"><figcaption>" + esc(caption) + "</figcaption></figure>\n";
  }
  void table(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows) {
    body += "<table><thead><tr>";
    for (const auto& h : head) body += "<th>" + esc(h) + "</th>";
    body += "</tr></thead><tbody>\n";
    for (const auto& r : rows) {
      body += "<tr>";
      for (const auto& c : r) body += "<td>" + esc(c) + "</td>";
      body += "</tr>\n";
    }
    body += "</tbody></table>\n";
  }
};

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

// One sentence at the top: the accuracy of each solution against the reference and the filter's health.
std::string headline(const fs::path& dir, const nlohmann::json& summary) {
  std::vector<std::string> parts;
  for (const auto& [file, name] : std::vector<std::pair<std::string, std::string>>{
           {"evaluation_smoothed.json", "smoothed"}, {"evaluation.json", "forward"}}) {
    if (!fs::exists(dir / file)) continue;
    try {
      const auto j = nlohmann::json::parse(read_text(dir / file));
      parts.push_back(fmt::format("{} horizontal RMS {} m (max {} m)", name, num(j, "horizontal_rms_m"),
                                  num(j, "horizontal_max_m")));
    } catch (const std::exception&) {  // reported by the accuracy section
    }
  }
  std::string s;
  for (size_t k = 0; k < parts.size(); ++k) s += (k ? "; " : "") + parts[k];
  if (!s.empty()) s[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(s[0])));
  if (!summary.is_null()) {
    const auto* healthy = at_path(summary, "health.healthy");
    const long long reinit = count_at(summary, "health.reinitializations");
    if (healthy) {
      s += (s.empty() ? "Filter " : ". Filter ") + std::string(healthy->get<bool>() ? "healthy" : "NOT healthy");
      if (reinit >= 0) s += fmt::format(", {} re-initialization{}", reinit, reinit == 1 ? "" : "s");
    }
  }
  return s.empty() ? "" : "<p class=\"headline\" id=\"headline\">" + esc(s) + ".</p>\n";
}

// Accuracy against the reference: seed 004's bins (Tables 1-2), then the statistics, one row per solution.
void evaluation_section(Html& h, const fs::path& dir) {
  std::vector<std::vector<std::string>> rows;
  bool closure = false;
  std::vector<nlohmann::json> evs;
  std::vector<std::string> names;
  for (const auto& [file, name] : std::vector<std::pair<std::string, std::string>>{
           {"evaluation.json", "forward / as written"}, {"evaluation_smoothed.json", "RTS smoothed"}}) {
    if (!fs::exists(dir / file)) continue;
    try {
      evs.push_back(nlohmann::json::parse(read_text(dir / file)));
      names.push_back(name);
      closure = closure || evs.back().contains("closure_m");
    } catch (const std::exception& e) {
      h.warnings.push_back(file + ": " + e.what());
    }
  }
  for (size_t k = 0; k < evs.size(); ++k) {
    const auto& j = evs[k];
    const auto b = j.value("bins_pct", nlohmann::json::object());
    const auto cs = j.value("consistency", nlohmann::json::object());
    std::vector<std::string> r{names[k],
                               num(b, "lt5", "{:.1f}"),
                               num(b, "5to10", "{:.1f}"),
                               num(b, "10to20", "{:.1f}"),
                               num(b, "ge20", "{:.1f}"),
                               num(j, "horizontal_rms_m"),
                               num(j, "horizontal_p95_m"),
                               num(j, "horizontal_max_m"),
                               num(j, "vertical_rms_m"),
                               num(cs, "inside_3sigma_pct", "{:.1f}"),
                               num(j, "availability_pct", "{:.1f}"),
                               j.contains("epochs_compared") ? pretty(j["epochs_compared"]) : "–"};
    if (closure) {
      r.push_back(j.contains("closure_m") ? num(j, "closure_m") + " (" + num(j, "closure_pct_of_distance") + " %)"
                                          : "–");
    }
    rows.push_back(std::move(r));
  }
  if (rows.empty()) return;
  h.section("Accuracy against the reference");
  h.para("Horizontal error distribution in the layout of seed 004 Tables 1-2 (percent of epochs), then the "
         "statistics of evaluation.json (metres); \"inside 3σ\": share of epochs whose horizontal error is inside the "
         "solution's own 3σ.");
  std::vector<std::string> head{"solution", "< 5 m %", "5-10 m %", "10-20 m %", "≥ 20 m %", "RMS", "p95", "max",
                                "vertical RMS", "inside 3σ %", "availability %", "epochs"};
  if (closure) head.push_back("closure m (% of distance)");
  h.table(head, rows);
}

// Health of the run: what was rejected, re-initialized, skipped; then the report's own warnings (filled in last).
std::string health_html(const nlohmann::json& j, const std::vector<std::string>& warnings) {
  std::vector<std::pair<std::string, std::string>> rows;
  if (!j.is_null()) {
    if (const auto* v = at_path(j, "health.healthy")) {
      rows.push_back({"filter health", v->get<bool>() ? "healthy (covariance checks passed)" : "NOT healthy"});
    }
    if (const long long n = count_at(j, "health.reinitializations"); n >= 0) {
      rows.push_back({"re-initializations", fmt::format("{}", n)});
    }
    const long long read = count_at(j, "accounting.gnss_measurements.read");
    const long long fault = count_at(j, "gnss.code.innovation_fault");
    if (fault >= 0) {
      const long long persistent = std::max(0LL, count_at(j, "gnss.code.persistent_fault"));
      rows.push_back({"GNSS code rejected by fault detection",
                      share(fault + persistent, read) +
                          (persistent > 0 ? fmt::format(", {} of them as persistent faults", persistent) : "")});
    }
    if (const long long n = count_at(j, "gnss.doppler.innovation_fault"); n >= 0) {
      rows.push_back({"GNSS Doppler rejected by fault detection", fmt::format("{}", n)});
    }
    if (const long long n = count_at(j, "gnss.code.below_elevation_mask"); n >= 0) {
      rows.push_back({"GNSS code below the elevation mask", share(n, read)});
    }
    const long long no_base = count_at(j, "gnss.epochs_skipped_no_base");
    const long long outside = count_at(j, "gnss.epochs_outside_imu_span");
    if (no_base >= 0 || outside >= 0) {
      rows.push_back({"GNSS epochs skipped", fmt::format("{} without base, {} outside the IMU span of {} read",
                                                         std::max(0LL, no_base), std::max(0LL, outside),
                                                         std::max(0LL, count_at(j, "gnss.epochs_read")))});
    }
    const long long imu_read = count_at(j, "accounting.imu_samples.read");
    if (imu_read >= 0) {
      rows.push_back({"IMU samples rejected / skipped",
                      fmt::format("{} / {} of {}", std::max(0LL, sum_counts(j, "accounting.imu_samples.rejected")),
                                  std::max(0LL, sum_counts(j, "accounting.imu_samples.skipped")), imu_read)});
    }
    if (const long long n = count_at(j, "imu.saturation.samples"); n > 0) {
      rows.push_back({"IMU samples at saturation", fmt::format("{} in {} runs ({} reconstructed)", n,
                                                               count_at(j, "imu.saturation.runs"),
                                                               count_at(j, "imu.saturation.runs_reconstructed"))});
    }
    if (const long long n = count_at(j, "zupt.updates"); n >= 0) {
      std::string z = fmt::format("{} ZUPT updates", n);
      if (const long long zr = count_at(j, "zupt.zaru_updates"); zr >= 0) z += fmt::format(", {} ZARU", zr);
      if (const long long g = count_at(j, "zupt.zaru_rejected_by_gate"); g > 0) z += fmt::format(" ({} gated out)", g);
      if (const long long c = count_at(j, "zupt.short_stance_interval_ends"); c > 0) {
        z += fmt::format("; {} stances shorter than a mechanization interval closed their own", c);
      }
      rows.push_back({"stance updates", z});
    }
    if (const auto* v = at_path(j, "smoother.message")) rows.push_back({"smoother", pretty(*v)});
  }
  std::string html = "<h2>Health</h2>\n";
  if (rows.empty()) html += "<p>No run summary (summary.json) in this folder.</p>\n";
  if (!rows.empty()) {
    html += "<table class=\"kv\"><tbody>\n";
    for (const auto& [k, v] : rows) html += "<tr><th>" + esc(k) + "</th><td>" + esc(v) + "</td></tr>\n";
    html += "</tbody></table>\n";
  }
  std::vector<std::string> events;
  if (!j.is_null()) {
    if (const auto* e = at_path(j, "health.events"); e && e->is_array()) {
      for (const auto& x : *e) events.push_back(pretty(x));
    }
  }
  if (!events.empty()) {
    html += "<p>Health events:</p><ul>";
    for (const auto& e : events) html += "<li class=\"warn\">" + esc(e) + "</li>";
    html += "</ul>\n";
  }
  if (warnings.empty()) {
    html += "<p id=\"report-warnings\">Report warnings: none.</p>\n";
  } else {
    html += "<p id=\"report-warnings\">Report warnings (parts left out of this report):</p><ul>";
    for (const auto& w : warnings) html += "<li class=\"warn\">" + esc(w) + "</li>";
    html += "</ul>\n";
  }
  return html;
}

// Every key of summary.json, flattened to dotted names, values rounded; collapsed at the end of the page.
std::string appendix_html(const nlohmann::json& j) {
  if (j.is_null()) return "";
  std::vector<std::pair<std::string, std::string>> rows;
  std::function<void(const std::string&, const nlohmann::json&)> walk = [&](const std::string& key,
                                                                           const nlohmann::json& v) {
    if (v.is_object() && !v.empty()) {
      for (auto it = v.begin(); it != v.end(); ++it) walk(key.empty() ? it.key() : key + "." + it.key(), it.value());
    } else {
      rows.push_back({key, pretty(v)});
    }
  };
  walk("", j);
  std::string html = fmt::format(
      "<details id=\"appendix\"><summary>Appendix: the full run summary (summary.json, {} entries)</summary>\n"
      "<table class=\"kv\"><tbody>\n",
      rows.size());
  for (const auto& [k, v] : rows) html += "<tr><th>" + esc(k) + "</th><td>" + esc(v) + "</td></tr>\n";
  html += "</tbody></table></details>\n";
  return html;
}

void outage_section(Html& h, const fs::path& d, const fs::path& run_dir) {
  auto rms = read_csv_table((d / "rms_vs_time.csv").string());
  if (!rms) {
    h.warnings.push_back(rms.error().message);
    return;
  }
  nlohmann::json j;
  if (fs::exists(d / "summary.json")) {
    try {
      j = nlohmann::json::parse(read_text(d / "summary.json"));
    } catch (const std::exception& e) {
      h.warnings.push_back((d / "summary.json").string() + ": " + e.what());
    }
  }
  const std::string rel = fs::relative(d, run_dir).string();
  std::string kind = "outage study";
  if (j.contains("keep_sats")) {
    const int keep = j["keep_sats"].get<int>();
    kind = keep == 0 ? "full GNSS outages" : fmt::format("partial outages, {} satellites kept", keep);
  }
  h.section(fmt::format("Outage study: {} ({})", kind, rel == "." ? std::string("this folder") : rel));
  if (!j.is_null()) {
    std::vector<std::vector<std::string>> rows;
    rows.push_back({"forward", num(j, "max_error_m"), num(j, "max_rms_m"), num(j, "rms_at_end_m")});
    if (j.contains("smoothed")) {
      rows.push_back({"smoothed", num(j["smoothed"], "max_error_m"), num(j["smoothed"], "max_rms_m"),
                      num(j["smoothed"], "rms_at_end_m")});
    }
    h.para(fmt::format("{} windows of {} s; errors against the {}.", j.value("windows", 0),
                       num(j, "duration_s", "{:.0f}"),
                       j.value("against", std::string("run")) == "reference" ? "reference" : "run without outage"));
    h.table({"solution", "max error [m]", "max of RMS curve [m]", "RMS at window end [m]"}, rows);
  }
  if (auto w = read_csv_table((d / "outages.csv").string())) {
    // Column, heading, format ("" = integer). Only the columns the file has.
    const std::vector<std::array<std::string, 3>> cols{
        {"window", "window", ""},
        {"start_gps_tow_s", "start (GPS TOW s)", "{:.1f}"},
        {"sats_left_mean", "satellites left (mean)", "{:.1f}"},
        {"max_error_m", "max error m", "{:.2f}"},
        {"sigma_at_max_error_m", "σ at max error m", "{:.2f}"},
        {"end_error_m", "end error m", "{:.2f}"},
        {"end_sigma_m", "end σ m", "{:.2f}"},
        {"max_error_smoothed_m", "max error smoothed m", "{:.2f}"},
        {"end_error_smoothed_m", "end error smoothed m", "{:.2f}"}};
    std::vector<std::string> head;
    std::vector<const std::vector<double>*> data;
    std::vector<std::string> formats;
    for (const auto& [c, title, f] : cols) {
      if (const auto* col = w->column(c)) {
        head.push_back(title);
        data.push_back(col);
        formats.push_back(f);
      }
    }
    std::vector<std::vector<std::string>> rows;
    for (size_t i = 0; i < w->rows; ++i) {
      std::vector<std::string> r;
      for (size_t k = 0; k < data.size(); ++k) {
        const double v = (*data[k])[i];
        r.push_back(!std::isfinite(v)      ? "–"
                    : formats[k].empty() ? fmt::format("{:.0f}", v)
                                         : fmt::format(fmt::runtime(formats[k]), v));
      }
      rows.push_back(r);
    }
    if (!head.empty()) h.table(head, rows);
  }
  const auto* t = rms->column("t_since_outage_s");
  const auto* f = rms->column("rms_horizontal_m");
  const auto* s = rms->column("rms_horizontal_smoothed_m");
  if (t && f) {
    h.plot(outage_rms_plot("Outage: RMS horizontal error vs time since outage start (seed 004 Figure 17)", *t, *f,
                           s ? *s : std::vector<double>{}),
           "RMS across windows of the horizontal error, as a function of time since the outage started.");
  }
}

}  // namespace

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

Expected<ReportResult> run_report_command(const std::string& run_dir) {
  const fs::path dir(run_dir);
  if (!fs::is_directory(dir)) return make_error(run_dir + ": not a folder");
  ReportResult res;
  // The first screen answers what was asked (accuracy, trajectory, errors with their σ, health); the topics follow.
  Html h(res.warnings);
  Html topics(res.warnings);

  // Solutions of the run.
  std::vector<Solution> sols;
  for (const auto& [file, name] : std::vector<std::pair<std::string, std::string>>{
           {"solution.csv", "forward"}, {"smoothed.csv", "smoothed"}, {"gnss.csv", "GNSS-only LSQ"}}) {
    if (!fs::exists(dir / file)) continue;
    auto s = load_solution(dir / file, name);
    if (!s) {
      res.warnings.push_back(s.error().message);
      continue;
    }
    sols.push_back(std::move(*s));
  }
  std::vector<fs::path> outage_dirs;
  if (fs::exists(dir / "rms_vs_time.csv")) outage_dirs.push_back(dir);
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.is_directory() && fs::exists(e.path() / "rms_vs_time.csv")) outage_dirs.push_back(e.path());
  }
  std::sort(outage_dirs.begin(), outage_dirs.end());
  if (sols.empty() && outage_dirs.empty()) {
    return make_error(run_dir + ": nothing to report (expected solution.csv, smoothed.csv, gnss.csv or an outage "
                                "study's rms_vs_time.csv)");
  }
  std::string ref_name;
  const auto reference = load_reference(dir, res.warnings, ref_name);

  const nlohmann::json summary = run_summary(dir, res.warnings);
  evaluation_section(h, dir);
  h.body += "<!--HEALTH-->\n";

  if (!sols.empty()) {
    const char* colors[] = {"#1f77b4", "#d62728", "#ff7f0e"};
    const GpsTime t0 = sols.front().t.front();
    const Eigen::Vector3d p0 = reference && !reference->points.empty() && reference->frame == eval::Frame::kEcef
                                   ? reference->points.front().p
                                   : sols.front().p_e.front();
    // Map.
    std::vector<EnTrack> tracks;
    if (reference && reference->frame == eval::Frame::kEcef) {
      std::vector<Eigen::Vector3d> rp;
      for (const auto& p : reference->points) rp.push_back(p.p);
      tracks.push_back(to_en_track("reference", rp, p0, "#000000"));
    }
    for (size_t k = 0; k < sols.size(); ++k) tracks.push_back(to_en_track(sols[k].name, sols[k].p_e, p0, colors[k % 3]));
    h.section(reference ? "Trajectory and errors against the reference" : "Trajectory");
    h.row_open();
    h.plot(trajectory_plot("Trajectory in local East/North", tracks),
           reference ? "Solutions against the reference " + ref_name + " (origin: its first point)."
                     : "Solutions (no reference configured; origin: the first epoch).");

    // Errors against the reference.
    if (!reference) h.row_close();
    if (reference) {
      std::vector<ErrorSeries> hs;
      std::vector<std::vector<std::string>> seg_rows;
      std::optional<eval::Evaluation> forward_ev;
      for (size_t k = 0; k < sols.size(); ++k) {
        auto ev = eval::compare(trajectory_of(sols[k]), *reference, eval::CompareOptions{});
        if (!ev) {
          res.warnings.push_back(sols[k].name + " vs reference: " + ev.error().message);
          continue;
        }
        ErrorSeries s{sols[k].name, {}, {}, colors[k % 3]};
        for (const auto& e : ev->errors) {
          s.t_s.push_back(e.t - t0);
          s.value_m.push_back(e.horizontal_m);
        }
        hs.push_back(std::move(s));
        const auto v = eval::vertical_statistics(ev->errors);
        seg_rows.push_back({sols[k].name, "vertical (whole run)", fmt::format("{}", ev->errors.size()), "–", "–",
                            fmt::format("{:.2f}", v.rms_m), fmt::format("mean {:.2f}, sd {:.2f}, p95 |up| {:.2f}, "
                                                                        "max |up| {:.2f}",
                                                                        v.mean_m, v.std_m, v.p95_abs_m, v.max_abs_m)});
        for (const auto& sg : eval::segment_statistics(ev->errors, 120.0)) {
          seg_rows.push_back({sols[k].name, fmt::format("{:.0f}-{:.0f} s", sg.t_start - t0, sg.t_end - t0),
                              fmt::format("{}", sg.epochs), fmt::format("{:.2f}", sg.horizontal_rms_m),
                              fmt::format("{:.2f}", sg.horizontal_max_m), fmt::format("{:.2f}", sg.vertical_rms_m),
                              fmt::format("bias E {:.2f}, N {:.2f}", sg.horizontal_mean_e_m, sg.horizontal_mean_n_m)});
        }
        if (k == 0) forward_ev = std::move(*ev);
      }
      if (!hs.empty()) {
        h.plot(horizontal_error_plot("Horizontal error vs time", hs), "Horizontal error of each solution.");
        topics.section("Error distribution");
        topics.plot(error_cdf_plot("Horizontal error CDF", hs),
                    "Empirical cumulative distribution of the horizontal error.");
      }
      h.row_close();
      // +-3 sigma envelope of the first solution (forward) where it has sigma columns.
      const auto* sdn = sols.front().table.column("sd_n_m");
      const auto* sde = sols.front().table.column("sd_e_m");
      if (forward_ev && sdn && sde) {
        std::map<int64_t, size_t> row_of;
        const auto* wk = sols.front().table.column("gps_week");
        const auto* tow = sols.front().table.column("gps_tow_s");
        for (size_t i = 0; i < sols.front().table.rows; ++i) {
          if (std::isfinite((*wk)[i]) && std::isfinite((*tow)[i])) {
            row_of[GpsTime::from_week_tow(static_cast<int>((*wk)[i]), (*tow)[i]).ns()] = i;
          }
        }
        std::vector<double> t, en, ee, sn, se;
        for (const auto& e : forward_ev->errors) {
          auto it = row_of.find(e.t.ns());
          t.push_back(e.t - t0);
          ee.push_back(e.d_enu.x());
          en.push_back(e.d_enu.y());
          sn.push_back(it == row_of.end() ? NAN : (*sdn)[it->second]);
          se.push_back(it == row_of.end() ? NAN : (*sde)[it->second]);
        }
        h.row_open();
        h.plot(error_envelope_plot("North error of the " + sols.front().name + " solution with ±3σ", "North", t, en, sn),
               "North error and the filter's ±3σ envelope (sd_n_m of the solution).");
        h.plot(error_envelope_plot("East error of the " + sols.front().name + " solution with ±3σ", "East", t, ee, se),
               "East error and the filter's ±3σ envelope (sd_e_m of the solution).");
        h.row_close();
      }
      if (!seg_rows.empty()) {
        topics.section("Per-segment statistics (120 s segments)");
        topics.table({"solution", "segment", "epochs", "horizontal RMS [m]", "horizontal max [m]", "vertical RMS [m]",
                 "notes"},
                seg_rows);
      }
    }

    // Satellites and ZUPTs of the forward solution.
    const Solution& f = sols.front();
    std::vector<double> t;
    for (const auto& ti : f.t) t.push_back(ti - t0);
    auto column_at_positions = [&](const std::string& name) {
      std::vector<double> v;
      const auto* c = f.table.column(name);
      if (!c) return v;
      const auto* wk = f.table.column("gps_week");
      const auto* tow = f.table.column("gps_tow_s");
      for (size_t i = 0; i < f.table.rows; ++i) {
        if (std::isfinite((*wk)[i]) && std::isfinite((*tow)[i])) v.push_back((*c)[i]);
      }
      return v;
    };
    const auto used = column_at_positions("n_sats_used");
    const auto rejected = column_at_positions("n_sats_rejected");
    const auto zupt = column_at_positions("zupt");
    if (used.size() == t.size() && rejected.size() == t.size()) {
      topics.section("Satellites");
      topics.plot(satellites_plot(t, used, rejected), "Satellites used and rejected by fault detection per output epoch (" +
                                                     f.name + ").");
    }
    if (zupt.size() == t.size() && std::any_of(zupt.begin(), zupt.end(), [](double z) { return std::isfinite(z); })) {
      topics.section("Zero-velocity updates");
      topics.plot(zupt_plot(t, zupt, 30.0), "ZUPT flag at each output epoch and its 30 s moving fraction (" + f.name + ").");
    }
  }
  for (const auto& d : outage_dirs) outage_section(sols.empty() ? h : topics, d, dir);

  // Health last, so that it lists every warning the report itself ran into.
  const std::string health = health_html(summary, res.warnings);
  if (const size_t at = h.body.find("<!--HEALTH-->"); at != std::string::npos) {
    h.body.replace(at, std::string("<!--HEALTH-->").size(), health);
  }
  const bool accuracy_first = !h.sections.empty() && h.sections.front() == "Accuracy against the reference";
  h.sections.insert(h.sections.begin() + (accuracy_first ? 1 : 0), "Health");
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>pednav report</title>\n<style>"
      "body{font-family:sans-serif;max-width:1180px;margin:1em auto;padding:0 1em;color:#222}"
      "h1{margin:0.3em 0;font-size:1.6em}h2{margin:1em 0 0.3em;font-size:1.25em;border-bottom:1px solid #ddd}"
      ".headline{font-size:1.1em;background:#f6f8fa;border-left:4px solid #1f77b4;padding:0.4em 0.8em}"
      "table{border-collapse:collapse;margin:0.6em 0;font-size:0.85em;max-width:100%}"
      "td,th{border:1px solid #ccc;padding:3px 6px;text-align:right;overflow-wrap:anywhere}"
      "th{background:#f0f0f0;font-weight:600}td:first-child{text-align:left}"
      "table.kv th{text-align:left;white-space:nowrap}table.kv td{text-align:left}"
      "img.plot{max-width:100%;height:auto}figure{margin:0.6em 0}figcaption{font-size:0.85em;color:#555}"
      ".row{display:flex;flex-wrap:wrap;gap:1em}.row>figure{flex:1 1 460px;min-width:0}"
      ".warn{color:#a00}code{overflow-wrap:anywhere}details{margin:2em 0}summary{cursor:pointer;font-weight:600}"
      ".meta{color:#555;font-size:0.85em}"
      "</style></head><body>\n<h1>pednav report</h1>\n";
  html += "<p class=\"meta\">Run folder: <code>" + esc(fs::absolute(dir).string()) + "</code> · <span id=\"plot-status\">plots: " +
          std::to_string(h.plots + topics.plots) + " embedded</span> · <span id=\"layout-status\">layout: not checked</span></p>\n";
  html += headline(dir, summary);
  html += h.body;
  html += topics.body;
  html += appendix_html(summary);
  // After loading, state how many embedded plots the browser decoded, and whether anything runs past the right
  // edge of the window with every collapsed part open (both checked by the headless-browser test).
  html +=
      "<script>window.addEventListener('load',function(){var im=document.querySelectorAll('img.plot');var ok=0;"
      "for(var i=0;i<im.length;i++){if(im[i].complete&&im[i].naturalWidth>0)ok++;}"
      "document.getElementById('plot-status').textContent='plots shown: '+ok+' of '+im.length;"
      "var ds=document.querySelectorAll('details');var was=[];for(var i=0;i<ds.length;i++){was.push(ds[i].open);"
      "ds[i].open=true;}var W=document.documentElement.clientWidth;var bad='';var all=document.body.querySelectorAll('*');"
      "for(var i=0;i<all.length&&!bad;i++){var r=all[i].getBoundingClientRect();if(r.right>W+0.5)"
      "bad=all[i].tagName.toLowerCase()+' by '+Math.ceil(r.right-W)+' px';}"
      "if(!bad&&document.documentElement.scrollWidth>W)bad='page by '+(document.documentElement.scrollWidth-W)+' px';"
      "for(var i=0;i<ds.length;i++)ds[i].open=was[i];"
      "document.getElementById('layout-status').textContent=bad?'layout: overflow at '+W+' px ('+bad+')':"
      "'layout: fits '+W+' px';});</script>\n";
  html += "</body></html>\n";
  res.path = (dir / "report.html").string();
  res.plots = h.plots + topics.plots;
  res.sections = h.sections;
  res.sections.insert(res.sections.end(), topics.sections.begin(), topics.sections.end());
  if (!summary.is_null()) res.sections.push_back("Appendix: the full run summary");
  if (auto ok = write_file_atomic(res.path, html); !ok) return ok.error();
  return res;
}

}  // namespace pednav::io
