// SPDX-License-Identifier: BSD-2-Clause
// `pednav report OUTDIR`: the page (io/report.hpp); its parts are in io/report_common.cpp and io/report_sections.cpp.
#include "io/report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "eval/statistics.hpp"
#include "eval/trajectory.hpp"
#include "io/atomic_file.hpp"
#include "io/plot.hpp"
#include "io/plot_figures.hpp"
#include "io/report_internal.hpp"

namespace pednav::io {
namespace fs = std::filesystem;
using namespace report_detail;  // the parts of the page

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
    // With carrier phase: the status of the first solution's epochs (pednav run: solution.csv; pednav gnss: gnss.csv).
    carrier_status_section(topics, dir / (fs::exists(dir / "solution.csv") ? "solution.csv" : "gnss.csv"), t0, p0);
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
  html += fit_warnings_html(summary);
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
