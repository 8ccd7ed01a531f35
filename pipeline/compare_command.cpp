// SPDX-License-Identifier: BSD-2-Clause
#include "pipeline/compare_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "core/geodesy.hpp"
#include "eval/outage.hpp"
#include "eval/statistics.hpp"
#include "io/atomic_file.hpp"
#include "io/plot_figures.hpp"
#include "io/report.hpp"

namespace pednav::pipeline {

using namespace pednav::io;  // the readers, writers and configuration this use case drives
namespace {

const char* align_name(eval::Align a) {
  switch (a) {
    case eval::Align::kStart: return "start";
    case eval::Align::kStartPyshoe: return "start-pyshoe";
    case eval::Align::kBestFit2d: return "best-fit-2d";
    case eval::Align::kBestFit3d: return "best-fit-3d";
    default: return "none";
  }
}

// Consistency of the solution's own σ (pednav CSV solutions carry it), in its own axes: none after a rotating
// alignment or without σ.
std::optional<eval::ConsistencyStats> consistency_of(const eval::Evaluation& ev, const CompareArgs& args) {
  if (args.compare.align != eval::Align::kNone) return std::nullopt;
  const eval::ConsistencyStats cs = eval::consistency_statistics(ev.errors);
  if (cs.epochs == 0) return std::nullopt;
  return cs;
}

// trajectory_en.svg, error_vs_time.svg (+-3 sigma when the solution is a pednav CSV with sd_n_m/sd_e_m),
// error_cdf.svg. A plot that cannot be drawn is a warning, not a failure of the comparison.
void write_compare_plots(const eval::Evaluation& ev, const CompareArgs& args, const TrajectoryFile& sol,
                         const TrajectoryFile& ref) {
  const std::filesystem::path out(args.out_dir);
  auto write = [&](const std::string& name, const PlotSpec& p) {
    if (auto ok = write_plot_svg((out / name).string(), p); !ok) spdlog::warn("{} not written: {}", name, ok.error().message);
  };
  if (ref.trajectory.frame == eval::Frame::kEcef && sol.trajectory.frame == eval::Frame::kEcef &&
      !ref.trajectory.points.empty()) {
    std::vector<Eigen::Vector3d> rp, sp;
    for (const auto& p : ref.trajectory.points) rp.push_back(p.p);
    for (const auto& p : sol.trajectory.points) sp.push_back(p.p);
    const Eigen::Vector3d p0 = rp.front();
    write("trajectory_en.svg", trajectory_plot("Trajectory in local East/North",
                                               {to_en_track("reference", rp, p0, "#000000"),
                                                to_en_track("solution", sp, p0, "#1f77b4")}));
  }
  if (ev.errors.empty()) return;
  const GpsTime t0 = ev.errors.front().t;
  ErrorSeries hs{"solution", {}, {}, "#1f77b4"};
  for (const auto& e : ev.errors) {
    hs.t_s.push_back(e.t - t0);
    hs.value_m.push_back(e.horizontal_m);
  }
  write("error_cdf.svg", error_cdf_plot("Horizontal error CDF", {hs}));
  // Horizontal error with the +-3 sigma_h envelope (sigma_h = sqrt(sd_n^2 + sd_e^2), rotation-invariant) when the
  // solution has sigmas.
  bool has_sigma = false;
  for (const auto& e : ev.errors) has_sigma = has_sigma || std::isfinite(e.sd_enu_m.head<2>().norm());
  PlotSpec p = horizontal_error_plot("Horizontal error vs time", {hs});
  if (has_sigma) {
    PlotSeries band;
    band.title = "0..3σ_h (filter)";
    band.style = PlotStyle::kBand;
    band.color = "#1f77b4";
    for (const auto& e : ev.errors) {
      band.x.push_back(e.t - t0);
      band.y_low.push_back(0.0);
      band.y_high.push_back(3.0 * e.sd_enu_m.head<2>().norm());
    }
    p.series.insert(p.series.begin(), band);
  }
  write("error_vs_time.svg", p);
}

}  // namespace

std::string evaluation_json(const eval::Evaluation& ev, const CompareArgs& args, const TrajectoryFile& sol,
                            const TrajectoryFile& ref) {
  nlohmann::ordered_json j;
  j["epochs_compared"] = ev.epochs_compared;
  j["availability_pct"] = ev.availability_pct;
  j["horizontal_rms_m"] = ev.horizontal_rms_m;
  j["horizontal_mean_m"] = ev.horizontal_mean_m;
  j["horizontal_p50_m"] = ev.horizontal_p50_m;
  j["horizontal_p95_m"] = ev.horizontal_p95_m;
  j["horizontal_max_m"] = ev.horizontal_max_m;
  j["vertical_rms_m"] = ev.vertical_rms_m;
  j["vertical_mean_m"] = ev.vertical_mean_m;
  j["vertical_max_abs_m"] = ev.vertical_max_abs_m;
  j["bins_pct"] = {{"lt5", ev.bins_pct[0]}, {"5to10", ev.bins_pct[1]}, {"10to20", ev.bins_pct[2]}, {"ge20", ev.bins_pct[3]}};
  if (ev.has_closure) {
    j["closure_m"] = ev.closure_m;
    j["closure_pct_of_distance"] = ev.closure_pct_of_distance;
    j["distance_m"] = ev.distance_m;
  }
  if (const auto cs = consistency_of(ev, args)) {
    j["consistency"] = {{"epochs_with_sigma", cs->epochs},
                        {"inside_3sigma_pct", cs->inside_3sigma_pct},
                        {"inside_3sigma_vertical_pct", cs->inside_3sigma_vertical_pct},
                        {"mean_normalized_sq_horizontal", cs->mean_normalized_sq_horizontal},
                        {"max_normalized_horizontal", cs->max_normalized_horizontal}};
  }
  const eval::VerticalStats v = eval::vertical_statistics(ev.errors);
  j["vertical"] = {{"rms_m", v.rms_m}, {"mean_m", v.mean_m}, {"std_m", v.std_m}, {"p95_abs_m", v.p95_abs_m},
                   {"max_abs_m", v.max_abs_m}};
  nlohmann::ordered_json segs = nlohmann::json::array();
  for (const auto& sg : eval::segment_statistics(ev.errors, args.segment_s)) {
    segs.push_back({{"start_gps_tow_s", sg.t_start.tow_s()}, {"end_gps_tow_s", sg.t_end.tow_s()},
                    {"epochs", sg.epochs}, {"horizontal_rms_m", sg.horizontal_rms_m},
                    {"horizontal_max_m", sg.horizontal_max_m}, {"vertical_rms_m", sg.vertical_rms_m},
                    {"mean_e_m", sg.horizontal_mean_e_m}, {"mean_n_m", sg.horizontal_mean_n_m}});
  }
  j["segment_s"] = args.segment_s;
  j["segments"] = segs;
  j["reference_epochs"] = ev.reference_epochs;
  j["align"] = align_name(args.compare.align);
  j["time_tolerance_s"] = args.compare.time_tolerance_s;
  j["solution"] = {{"file", args.solution}, {"format", sol.format}, {"epochs", sol.trajectory.points.size()}};
  j["reference"] = {{"file", args.reference},
                    {"format", ref.format},
                    {"epochs", ref.trajectory.points.size()},
                    {"skipped_quality", ref.skipped_quality},
                    {"skipped_checksum", ref.skipped_checksum},
                    {"skipped_empty", ref.skipped_empty},
                    {"skipped_duplicate_time", ref.skipped_duplicate_time}};
  return j.dump(2) + "\n";
}

std::string evaluation_markdown(const eval::Evaluation& ev, const CompareArgs& args) {
  std::string s = fmt::format("# Evaluation\n\nSolution `{}` against reference `{}` (alignment: {}).\n\n", args.solution,
                              args.reference, align_name(args.compare.align));
  s += "| figure | value |\n|---|---|\n";
  s += fmt::format("| epochs compared | {} |\n| availability | {:.1f} % |\n", ev.epochs_compared, ev.availability_pct);
  s += fmt::format("| horizontal RMS | {:.3f} m |\n| horizontal mean | {:.3f} m |\n| horizontal p50 | {:.3f} m |\n",
                   ev.horizontal_rms_m, ev.horizontal_mean_m, ev.horizontal_p50_m);
  s += fmt::format("| horizontal p95 | {:.3f} m |\n| horizontal max | {:.3f} m |\n| vertical RMS | {:.3f} m |\n",
                   ev.horizontal_p95_m, ev.horizontal_max_m, ev.vertical_rms_m);
  if (ev.has_closure) {
    s += fmt::format("| closure | {:.3f} m ({:.2f} % of {:.1f} m) |\n", ev.closure_m, ev.closure_pct_of_distance,
                     ev.distance_m);
  }
  if (const auto cs = consistency_of(ev, args)) {
    s += fmt::format("| inside 3σ (N and E / U, the solution's own σ) | {:.1f} % / {:.1f} % of {} epochs |\n"
                     "| mean (e_E/σ_E)² + (e_N/σ_N)² (2 if consistent) / max \\|e\\|/σ | {:.2f} / {:.1f} |\n",
                     cs->inside_3sigma_pct, cs->inside_3sigma_vertical_pct, cs->epochs, cs->mean_normalized_sq_horizontal,
                     cs->max_normalized_horizontal);
  }
  const eval::VerticalStats v = eval::vertical_statistics(ev.errors);
  s += fmt::format("| vertical mean / sd | {:.3f} m / {:.3f} m |\n| vertical p95 abs / max abs | {:.3f} m / {:.3f} m |\n",
                   v.mean_m, v.std_m, v.p95_abs_m, v.max_abs_m);
  s += "\nHorizontal error distribution (layout of seed 004 Tables 1-2):\n\n| < 5 m | 5-10 m | 10-20 m | ≥ 20 m |\n|---|---|---|---|\n";
  s += fmt::format("| {:.1f} % | {:.1f} % | {:.1f} % | {:.1f} % |\n", ev.bins_pct[0], ev.bins_pct[1], ev.bins_pct[2],
                   ev.bins_pct[3]);
  const auto segs = eval::segment_statistics(ev.errors, args.segment_s);
  if (!segs.empty()) {
    s += fmt::format("\nPer-segment statistics ({:g} s segments; GPS seconds of week):\n\n", args.segment_s);
    s += "| start | end | epochs | horizontal RMS | horizontal max | vertical RMS | mean E | mean N |\n"
         "|---|---|---|---|---|---|---|---|\n";
    for (const auto& sg : segs) {
      s += fmt::format("| {:.1f} | {:.1f} | {} | {:.3f} m | {:.3f} m | {:.3f} m | {:.3f} m | {:.3f} m |\n",
                       sg.t_start.tow_s(), sg.t_end.tow_s(), sg.epochs, sg.horizontal_rms_m, sg.horizontal_max_m,
                       sg.vertical_rms_m, sg.horizontal_mean_e_m, sg.horizontal_mean_n_m);
    }
  }
  return s;
}

Expected<eval::Evaluation> run_compare(const CompareArgs& args) {
  auto sol = read_trajectory(args.solution, args.solution_read);
  if (!sol) return sol.error();
  auto ref = read_trajectory(args.reference, args.reference_read);
  if (!ref) return ref.error();
  auto ev = eval::compare(sol->trajectory, ref->trajectory, args.compare);
  if (!ev) return make_error(args.solution + " vs " + args.reference + ": " + ev.error().message);
  std::error_code ec;
  std::filesystem::create_directories(args.out_dir, ec);
  if (ec) return make_error(args.out_dir + ": cannot create output folder: " + ec.message());
  const std::filesystem::path out(args.out_dir);
  if (auto ok = write_file_atomic((out / "evaluation.json").string(), evaluation_json(*ev, args, *sol, *ref)); !ok) {
    return ok.error();
  }
  if (auto ok = write_file_atomic((out / "evaluation.md").string(), evaluation_markdown(*ev, args)); !ok) {
    return ok.error();
  }
  std::string csv = "gps_week,gps_tow_s,de_m,dn_m,du_m,horizontal_m\n";
  for (const auto& e : ev->errors) {
    csv += fmt::format("{},{:.3f},{:.4f},{:.4f},{:.4f},{:.4f}\n", e.t.week(), e.t.tow_s(), e.d_enu.x(), e.d_enu.y(),
                       e.d_enu.z(), e.horizontal_m);
  }
  if (auto ok = write_file_atomic((out / "errors.csv").string(), csv); !ok) return ok.error();
  std::vector<double> horizontal;
  for (const auto& e : ev->errors) horizontal.push_back(e.horizontal_m);
  const eval::Cdf cdf = eval::empirical_cdf(horizontal);
  std::string cdf_csv = "horizontal_m,fraction\n";
  for (size_t i = 0; i < cdf.value.size(); ++i) cdf_csv += fmt::format("{:.4f},{:.6f}\n", cdf.value[i], cdf.fraction[i]);
  if (auto ok = write_file_atomic((out / "error_cdf.csv").string(), cdf_csv); !ok) return ok.error();
  if (args.plots) write_compare_plots(*ev, args, *sol, *ref);
  return ev;
}

}  // namespace pednav::pipeline
