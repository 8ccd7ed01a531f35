// SPDX-License-Identifier: BSD-2-Clause
#include "io/report.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
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

void evaluation_section(Html& h, const fs::path& dir) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& [file, name] : std::vector<std::pair<std::string, std::string>>{
           {"evaluation.json", "forward / as written"}, {"evaluation_smoothed.json", "RTS smoothed"}}) {
    if (!fs::exists(dir / file)) continue;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(read_text(dir / file));
    } catch (const std::exception& e) {
      h.warnings.push_back(file + ": " + e.what());
      continue;
    }
    const auto b = j.value("bins_pct", nlohmann::json::object());
    rows.push_back({name, num(b, "lt5", "{:.1f}"), num(b, "5to10", "{:.1f}"), num(b, "10to20", "{:.1f}"),
                    num(b, "ge20", "{:.1f}"), num(j, "horizontal_rms_m"), num(j, "horizontal_mean_m"),
                    num(j, "horizontal_p95_m"), num(j, "horizontal_max_m"), num(j, "vertical_rms_m"),
                    num(j, "availability_pct", "{:.1f}"), num(j, "closure_m"), num(j, "closure_pct_of_distance")});
  }
  if (rows.empty()) return;
  h.section("Accuracy against the reference");
  h.para("Horizontal error distribution in the layout of seed 004 Tables 1-2 (percent of epochs), then the "
         "statistics of evaluation.json (metres).");
  h.table({"solution", "< 5 m %", "5-10 m %", "10-20 m %", ">= 20 m %", "RMS", "mean", "p95", "max", "vertical RMS",
           "availability %", "closure m", "closure % of distance"},
          rows);
}

void summary_section(Html& h, const fs::path& dir) {
  if (!fs::exists(dir / "summary.json")) return;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(read_text(dir / "summary.json"));
  } catch (const std::exception& e) {
    h.warnings.push_back(std::string("summary.json: ") + e.what());
    return;
  }
  if (j.contains("windows") && j.contains("keep_sats")) return;  // an outage study: its own section
  h.section("Run summary");
  std::vector<std::vector<std::string>> rows;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.value().is_object()) {
      for (auto jt = it.value().begin(); jt != it.value().end(); ++jt) {
        rows.push_back({it.key() + "." + jt.key(), jt.value().is_string() ? jt.value().get<std::string>()
                                                                          : jt.value().dump()});
      }
    } else {
      rows.push_back({it.key(), it.value().is_string() ? it.value().get<std::string>() : it.value().dump()});
    }
  }
  h.table({"key", "value"}, rows);
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
    std::vector<std::vector<std::string>> rows;
    const std::vector<std::string> cols{"window",        "start_gps_tow_s",      "sats_left_mean",
                                        "max_error_m",   "sigma_at_max_error_m", "end_error_m",
                                        "end_sigma_m",   "max_error_smoothed_m", "end_error_smoothed_m"};
    for (size_t i = 0; i < w->rows; ++i) {
      std::vector<std::string> r;
      for (const auto& c : cols) {
        const auto* col = w->column(c);
        r.push_back(col && std::isfinite((*col)[i]) ? fmt::format("{:.2f}", (*col)[i]) : "–");
      }
      rows.push_back(r);
    }
    h.table(cols, rows);
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
  Html h(res.warnings);

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

  summary_section(h, dir);
  evaluation_section(h, dir);

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
    h.section("Trajectory");
    h.plot(trajectory_plot("Trajectory in local East/North", tracks),
           reference ? "Solutions against the reference " + ref_name + " (origin: its first point)."
                     : "Solutions (no reference configured; origin: the first epoch).");

    // Errors against the reference.
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
        h.section("Errors against the reference");
        h.plot(horizontal_error_plot("Horizontal error vs time", hs), "Horizontal error of each solution.");
        h.plot(error_cdf_plot("Horizontal error CDF", hs), "Empirical cumulative distribution of the horizontal error.");
      }
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
        h.plot(error_envelope_plot("North error of the " + sols.front().name + " solution with ±3σ", "North", t, en, sn),
               "North error and the filter's ±3σ envelope (sd_n_m of the solution).");
        h.plot(error_envelope_plot("East error of the " + sols.front().name + " solution with ±3σ", "East", t, ee, se),
               "East error and the filter's ±3σ envelope (sd_e_m of the solution).");
      }
      if (!seg_rows.empty()) {
        h.section("Per-segment statistics (120 s segments)");
        h.table({"solution", "segment", "epochs", "horizontal RMS [m]", "horizontal max [m]", "vertical RMS [m]",
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
      h.section("Satellites");
      h.plot(satellites_plot(t, used, rejected), "Satellites used and rejected by fault detection per output epoch (" +
                                                     f.name + ").");
    }
    if (zupt.size() == t.size() && std::any_of(zupt.begin(), zupt.end(), [](double z) { return std::isfinite(z); })) {
      h.section("Zero-velocity updates");
      h.plot(zupt_plot(t, zupt, 30.0), "ZUPT flag at each output epoch and its 30 s moving fraction (" + f.name + ").");
    }
  }
  for (const auto& d : outage_dirs) outage_section(h, d, dir);

  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>pednav report</title>\n<style>"
      "body{font-family:sans-serif;max-width:1000px;margin:2em auto;color:#222}"
      "table{border-collapse:collapse;margin:1em 0;font-size:0.9em}td,th{border:1px solid #ccc;padding:3px 8px;"
      "text-align:right}th{background:#f0f0f0}td:first-child{text-align:left}img.plot{max-width:100%}"
      "figure{margin:1em 0}figcaption{font-size:0.9em;color:#555}.warn{color:#a00}"
      "</style></head><body>\n<h1>pednav report</h1>\n";
  html += "<p>Run folder: <code>" + esc(fs::absolute(dir).string()) + "</code></p>\n";
  html += "<p id=\"plot-status\">plots: " + std::to_string(h.plots) + " embedded</p>\n";
  html += h.body;
  if (!res.warnings.empty()) {
    html += "<h2>Warnings</h2><ul>";
    for (const auto& w : res.warnings) html += "<li class=\"warn\">" + esc(w) + "</li>";
    html += "</ul>\n";
  }
  // After loading, state how many embedded plots the browser decoded (checked by the headless-browser test).
  html +=
      "<script>window.addEventListener('load',function(){var im=document.querySelectorAll('img.plot');var ok=0;"
      "for(var i=0;i<im.length;i++){if(im[i].complete&&im[i].naturalWidth>0)ok++;}"
      "document.getElementById('plot-status').textContent='plots shown: '+ok+' of '+im.length;});</script>\n";
  html += "</body></html>\n";
  res.path = (dir / "report.html").string();
  res.plots = h.plots;
  res.sections = h.sections;
  if (auto ok = write_file_atomic(res.path, html); !ok) return ok.error();
  return res;
}

}  // namespace pednav::io
