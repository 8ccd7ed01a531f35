// SPDX-License-Identifier: BSD-2-Clause
// report.html: the headline, accuracy, health, appendix and outage sections (io/report_internal.hpp).
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "io/plot_figures.hpp"
#include "io/report_internal.hpp"

namespace pednav::io::report_detail {

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

// The run's fit warnings (summary.json `warnings`, docs/fusion.md §15) under the headline; nothing without any.
std::string fit_warnings_html(const nlohmann::json& summary) {
  const auto* w = summary.is_null() ? nullptr : at_path(summary, "warnings");
  if (!w || !w->is_array() || w->empty()) return "";
  std::string h = "<div class=\"warn\" id=\"fit-warnings\"><p>The log does not fit the model here:</p><ul>\n";
  for (const auto& x : *w) {
    const std::string msg = x.contains("message") && x["message"].is_string() ? x["message"].get<std::string>() : "";
    const std::string hint = x.contains("hint") && x["hint"].is_string() ? x["hint"].get<std::string>() : "";
    h += "<li>" + esc(msg) + (hint.empty() ? "" : ": " + esc(hint)) + "</li>\n";
  }
  return h + "</ul></div>\n";
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
    // Windows the reference could not score (docs/outage.md §1, step 5): named with the reason, left out above.
    if (j.contains("window_list") && j["window_list"].is_array()) {
      int k = 0;
      for (const auto& w : j["window_list"]) {
        ++k;
        if (w.value("scored", true)) continue;
        h.para(fmt::format("Window {} (start {} s GPS TOW) not scored: {}.", k, num(w, "start_gps_tow_s", "{:.0f}"),
                           w.value("unscored_reason", std::string("no reason given"))));
      }
    }
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

}  // namespace pednav::io::report_detail
