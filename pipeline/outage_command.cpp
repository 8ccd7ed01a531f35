// SPDX-License-Identifier: BSD-2-Clause
#include "pipeline/outage_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/geodesy.hpp"
#include "fusion/ambiguity.hpp"
#include "fusion/engine.hpp"
#include "gnss/measurement.hpp"
#include "gnss/rtklib/rinex.hpp"
#include "io/atomic_file.hpp"
#include "io/imu_csv.hpp"
#include "io/log.hpp"
#include "io/plot.hpp"
#include "pipeline/run_command.hpp"
#include "io/solution_writer.hpp"
#include "io/trajectory_io.hpp"

namespace pednav::pipeline {

using namespace pednav::io;  // the readers, writers and configuration this use case drives
namespace {

using SatKeep = std::map<int64_t, std::vector<gnss::SatId>>;  // rover epoch time [ns] -> satellites kept

// The inputs of a tc run, read once and shared by every window's run.
using Data = RunInputs;

Expected<Data> load(const RunConfig& c) { return load_run_inputs(c); }

fusion::EngineInputs inputs(const Data& d) { return d.engine_inputs(); }

// Seconds from `from` to the first forward epoch at or after it with status fixed; NaN when there is none.
double first_fix_after_s(const std::vector<fusion::EpochOutput>& sol, GpsTime from) {
  for (const auto& e : sol) {
    if (e.t < from || static_cast<fusion::SolutionStatus>(e.solution_status) != fusion::SolutionStatus::kFixed) continue;
    return e.t - from;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

bool system_selected(const std::vector<gnss::System>& systems, gnss::System s) {
  return std::find(systems.begin(), systems.end(), s) != systems.end();
}

// Position of the run without outage nearest in time to t [ECEF m] (elevations only need ~km accuracy).
Eigen::Vector3d position_near(const std::vector<fusion::EpochOutput>& epochs, GpsTime t) {
  auto it = std::lower_bound(epochs.begin(), epochs.end(), t,
                             [](const fusion::EpochOutput& e, GpsTime x) { return e.t < x; });
  if (it == epochs.end()) --it;
  if (it != epochs.begin() && std::abs(std::prev(it)->t - t) < std::abs(it->t - t)) --it;
  return it->nav.p_eb_e;
}

// Satellites the partial outage keeps at every rover epoch inside a window: among those the engine could use
// (selected system, pseudorange, ephemeris, above the elevation mask and the C/N0 floor, seen by the base), the
// N highest (seed 004: "rejecting the lowest elevation satellite ... as long as the number of satellites was
// greater than two or three") or strongest.
SatKeep plan_partial(const Data& d, const std::vector<fusion::EpochOutput>& nominal,
                     const std::vector<eval::OutageWindow>& windows, int keep, eval::KeepBy by) {
  SatKeep plan;
  const auto& o = d.options;
  for (const gnss::ObsEpoch& re : d.rover->epochs) {
    if (std::none_of(windows.begin(), windows.end(), [&](const auto& w) { return w.contains(re.time); })) continue;
    const Eigen::Vector3d p_e = position_near(nominal, re.time);
    const gnss::ObsEpoch* be = nullptr;
    if (d.base && o.base_position_e) {
      const auto& bs = d.base->epochs;
      auto it = std::lower_bound(bs.begin(), bs.end(), re.time,
                                 [](const gnss::ObsEpoch& e, GpsTime x) { return e.time < x; });
      double best = o.max_base_age_s;
      for (auto jt : {it, it == bs.begin() ? it : std::prev(it)}) {
        if (jt != bs.end() && std::abs(jt->time - re.time) <= best) {
          best = std::abs(jt->time - re.time);
          be = &*jt;
        }
      }
    }
    std::vector<eval::SatCandidate> cand;
    for (size_t i = 0; i < re.sats.size(); ++i) {
      const gnss::SatObs& so = re.sats[i];
      if (!system_selected(o.systems, so.sat.system) || std::isnan(so.pseudorange_m)) continue;
      if (!std::isnan(so.cn0_dbhz) && so.cn0_dbhz < o.min_cn0_dbhz) continue;
      if (d.base) {
        if (!be) continue;
        auto bt = std::find_if(be->sats.begin(), be->sats.end(), [&](const gnss::SatObs& b) { return b.sat == so.sat; });
        if (bt == be->sats.end() || std::isnan(bt->pseudorange_m)) continue;
      }
      auto st = gnss::satellite_state_at_reception(*d.nav, so.sat, re.time, so.pseudorange_m);
      if (!st) continue;
      const double el = gnss::elevation_azimuth(p_e, st->p_es_e).elevation;
      if (el < o.elevation_mask_rad) continue;
      cand.push_back({static_cast<int>(i), el, so.cn0_dbhz});
    }
    std::vector<gnss::SatId> kept;
    for (int i : eval::select_kept_satellites(cand, keep, by)) kept.push_back(re.sats[static_cast<size_t>(i)].sat);
    plan[re.time.ns()] = std::move(kept);
  }
  return plan;
}

eval::Trajectory to_trajectory(const std::vector<fusion::EpochOutput>& epochs) {
  eval::Trajectory t;
  for (const auto& e : epochs) t.points.push_back({e.t, e.nav.p_eb_e});
  return t;
}

// Horizontal error of a run's outputs inside [start, end] of a window against a reference trajectory.
Expected<eval::WindowErrors> window_errors(const std::vector<fusion::EpochOutput>& epochs,
                                           const eval::Trajectory& reference, const eval::OutageWindow& w) {
  eval::Trajectory sol;
  std::map<int64_t, double> sigma_h_m;  // solution time [GPST ns] -> its horizontal 1σ √(P_nn + P_ee)
  for (const auto& e : epochs) {
    if (!(e.t < w.start) && !(w.end() < e.t)) {
      sol.points.push_back({e.t, e.nav.p_eb_e});
      sigma_h_m[e.t.ns()] = std::sqrt(std::max(0.0, e.cov_p_n(0, 0) + e.cov_p_n(1, 1)));
    }
  }
  eval::WindowErrors we;
  we.window = w;
  if (sol.points.empty()) return we;
  auto ev = eval::compare(sol, reference, eval::CompareOptions{});
  if (!ev) return make_error(ev.error().message);
  for (const auto& e : ev->errors) {
    we.t_since_s.push_back(e.t - w.start);
    we.horizontal_m.push_back(e.horizontal_m);
    const auto it = sigma_h_m.find(e.t.ns());
    we.sigma_horizontal_m.push_back(it == sigma_h_m.end() ? NAN : it->second);
  }
  return we;
}

OutageFigures figures(const std::vector<eval::WindowErrors>& errs) {
  OutageFigures f;
  double sum_end2 = 0.0;
  int n_end = 0;
  for (const auto& w : errs) {
    f.per_window.push_back(eval::window_stats(w));
    f.max_error_m = std::max(f.max_error_m, f.per_window.back().max_m);
    if (f.per_window.back().samples > 0) {
      sum_end2 += f.per_window.back().end_m * f.per_window.back().end_m;
      ++n_end;
    }
  }
  f.rms_at_end_m = n_end > 0 ? std::sqrt(sum_end2 / n_end) : 0.0;
  f.rms = eval::rms_vs_time(errs, 1.0);
  for (double r : f.rms.rms_m) f.max_rms_m = std::max(f.max_rms_m, r);
  return f;
}

nlohmann::ordered_json figures_json(const OutageFigures& f) {
  return {{"max_error_m", f.max_error_m}, {"max_rms_m", f.max_rms_m}, {"rms_at_end_m", f.rms_at_end_m}};
}

// A window's run as solution.csv rows (the columns of pednav run; position of the IMU).
std::vector<SolutionRow> solution_rows(const std::vector<fusion::EpochOutput>& epochs) {
  std::vector<SolutionRow> rows;
  rows.reserve(epochs.size());
  for (const auto& e : epochs) rows.push_back(solution_row(e));
  return rows;
}

// Why a reference cannot score window w: the epochs it has around the window, or the comparison's own message.
std::string unscorable_reason(const eval::Trajectory& reference, const eval::OutageWindow& w,
                              const std::string& error) {
  const auto& pts = reference.points;
  const auto after = std::lower_bound(pts.begin(), pts.end(), w.start,
                                      [](const eval::TrajectoryPoint& p, GpsTime t) { return p.t < t; });
  if (after == pts.end() || w.end() < after->t) {
    const std::string before = after == pts.begin() ? std::string("none") : std::prev(after)->t.to_string();
    return fmt::format("the reference has no epoch from {} to {} (nearest before: {}; after: {})", w.start.to_string(),
                       w.end().to_string(), before, after == pts.end() ? std::string("none") : after->t.to_string());
  }
  return error;
}

// A CSV cell of free text: no comma, quote or line break (outages.csv is read by splitting at commas).
std::string csv_text(std::string s) {
  for (char& ch : s) {
    if (ch == ',') ch = ';';
    if (ch == '"' || ch == '\n' || ch == '\r') ch = ' ';
  }
  return s;
}

// A CSV cell: the value, or empty when there is none (not `have`, or not finite).
std::string fmt_opt(double v, bool have) { return have && std::isfinite(v) ? fmt::format("{:.3f}", v) : ""; }

}  // namespace

Expected<OutageResult> run_outage_command(const RunConfig& given, const OutageArgs& a) {
  const auto wall0 = std::chrono::steady_clock::now();
  auto as_tc = tc_config(given, "pednav outage");
  if (!as_tc) return as_tc.error();
  const RunConfig& c = *as_tc;
  if (a.keep_sats < 0) return make_error("--keep-sats: expected >= 0 (0 = full outage), got " + std::to_string(a.keep_sats));
  if (a.against != "auto" && a.against != "reference" && a.against != "run") {
    return make_error("--against: expected auto, reference or run, got '" + a.against + "'");
  }
  if (a.against == "reference" && c.reference.file.empty()) {
    return make_error(c.source_file + ": --against reference: the configuration has no reference.file");
  }
  auto data = load(c);
  if (!data) return data.error();
  const Data& d = *data;
  std::optional<eval::Trajectory> reference;
  OutageResult res;
  res.against = a.against == "run" || (a.against == "auto" && c.reference.file.empty()) ? "run" : "reference";
  if (res.against == "reference") {
    TrajectoryReadOptions ro;
    if (auto f = parse_trajectory_format(c.reference.format)) ro.format = *f;
    ro.nmea_qualities = std::set<int>(c.reference.nmea_qualities.begin(), c.reference.nmea_qualities.end());
    auto ref = read_trajectory(c.reference.file, ro);
    if (!ref) return ref.error();
    reference = std::move(ref->trajectory);
  }

  // The run without outage: convergence time, satellite geometry, and the error baseline.
  spdlog::info("outage study: run without outage");
  auto nominal = fusion::run_forward(inputs(d), d.options);
  if (!nominal) return make_error(c.source_file + ": " + nominal.error().message);
  res.has_smoothed = nominal->summary.smoothed;
  if (a.start_tow_s.empty()) {
    // Converged: the heading initialization is over (the epochs after the span the heading was fitted on: a window
    // overlapping it would change the initialization itself, since the mask also applies to the epoch solutions
    // the heading is fitted to) and the horizontal and yaw sigmas are below the thresholds.
    const std::optional<GpsTime> init_end = nominal->summary.heading_init_end;
    std::optional<GpsTime> converged;
    for (const auto& e : nominal->epochs) {
      const double sd_h = std::sqrt(std::max(0.0, e.cov_p_n(0, 0) + e.cov_p_n(1, 1)));
      if ((!init_end || e.t > *init_end) && sd_h <= a.converged_sigma_horizontal_m &&
          e.sd_yaw_rad * kRadToDeg <= a.converged_sigma_yaw_deg) {
        converged = e.t;
        break;
      }
    }
    if (!converged) {
      return make_error(fmt::format("{}: the run without outage never converged (after the heading initialization, "
                                    "horizontal sigma <= {} m and yaw sigma <= {} deg); lower the thresholds with "
                                    "--converged-sigma-m/--converged-yaw-deg or give --starts",
                                    c.source_file, a.converged_sigma_horizontal_m,
                                    a.converged_sigma_yaw_deg));
    }
    spdlog::info("converged at {} (+{:.0f} s settle)", converged->to_string(), a.settle_s);
    // Against a reference, each window goes where the reference covers it (a real RTK-fixed track has gaps; issue 49
    // item 8); against the run without outage, which covers everything, evenly.
    eval::ReferenceCoverage coverage;
    if (reference) {
      for (const auto& p : reference->points) coverage.epochs.push_back(p.t);
      coverage.max_gap_s = eval::CompareOptions{}.max_interp_gap_s;
    }
    auto w = reference ? eval::place_windows_covered(converged->plus_s(a.settle_s), nominal->epochs.back().t,
                                                     a.windows, a.duration_s, coverage)
                       : eval::place_windows_evenly(converged->plus_s(a.settle_s), nominal->epochs.back().t,
                                                    a.windows, a.duration_s);
    if (!w) return make_error(c.source_file + ": " + w.error().message);
    res.windows = std::move(*w);
  } else {
    std::vector<GpsTime> starts;
    const int week = nominal->epochs.front().t.week();
    for (double tow : a.start_tow_s) starts.push_back(GpsTime::from_week_tow(week, tow));
    auto w = eval::explicit_windows(starts, a.duration_s);
    if (!w) return w.error();
    res.windows = std::move(*w);
    for (const auto& win : res.windows) {
      if (win.start < nominal->epochs.front().t || nominal->epochs.back().t < win.end()) {
        return make_error(fmt::format("--starts: window {} .. {} is outside the run ({} .. {})", win.start.to_string(),
                                      win.end().to_string(), nominal->epochs.front().t.to_string(),
                                      nominal->epochs.back().t.to_string()));
      }
    }
  }

  auto plan = std::make_shared<SatKeep>();
  if (a.keep_sats > 0) *plan = plan_partial(d, nominal->epochs, res.windows, a.keep_sats, a.keep_by);

  // One run per window (independent: each window's filter starts from GNSS-aided conditions).
  const size_t nw = res.windows.size();
  std::vector<std::optional<Expected<fusion::EngineResult>>> runs(nw);
  std::atomic<size_t> next{0}, done{0};
  std::mutex progress_mutex;
  Progress progress("outage windows", static_cast<int64_t>(nw), progress_enabled());
  auto worker = [&] {
    for (size_t k = next++; k < nw; k = next++) {
      fusion::EngineInputs in = inputs(d);
      const eval::OutageWindow w = res.windows[k];
      const int keep = a.keep_sats;
      in.gnss_mask = [w, keep, plan](gnss::ObsEpoch& e) {
        if (!w.contains(e.time)) return;
        if (keep == 0) {
          e.sats.clear();
          return;
        }
        auto it = plan->find(e.time.ns());
        if (it == plan->end()) {
          e.sats.clear();
          return;
        }
        const auto& kept = it->second;
        std::erase_if(e.sats, [&](const gnss::SatObs& s) {
          return std::find(kept.begin(), kept.end(), s.sat) == kept.end();
        });
      };
      runs[k] = fusion::run_forward(in, d.options);
      std::lock_guard<std::mutex> lock(progress_mutex);
      progress.update(static_cast<int64_t>(++done));
    }
  };
  std::vector<std::thread> pool;
  for (int j = 1; j < std::max(1, a.jobs); ++j) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  progress.finish();

  // Errors per window: forward and smoothed, against the chosen reference and against the run without outage.
  std::vector<eval::WindowErrors> ef, es, ef_run, es_run;
  res.unscored_reason.assign(nw, std::string());
  const eval::Trajectory nominal_fwd = to_trajectory(nominal->epochs);
  const eval::Trajectory nominal_smo = to_trajectory(nominal->smoothed);
  for (size_t k = 0; k < nw; ++k) {
    if (!*runs[k]) return make_error(fmt::format("{}: outage window {} ({}): {}", c.source_file, k + 1,
                                                 res.windows[k].start.to_string(), runs[k]->error().message));
    const fusion::EngineResult& r = **runs[k];
    res.epochs_masked.push_back(r.summary.gnss_epochs_masked);
    if (d.options.carrier) {  // re-fix after the window (docs/outage.md §1.1)
      res.carrier = true;
      res.refix_s.push_back(first_fix_after_s(r.epochs, res.windows[k].end()));
      res.nominal_fix_s.push_back(first_fix_after_s(nominal->epochs, res.windows[k].start));
    }
    auto add = [&](std::vector<eval::WindowErrors>& dst, const std::vector<fusion::EpochOutput>& sol,
                   const eval::Trajectory& ref) -> Expected<void> {
      auto we = window_errors(sol, ref, res.windows[k]);
      if (!we) return make_error("window at " + res.windows[k].start.to_string() + ": " + we.error().message);
      dst.push_back(std::move(*we));
      return {};
    };
    // Against the reference a window may be unscorable (no reference epoch inside it): it is reported with the reason
    // and left out of the figures, and the study goes on with the other windows.
    auto add_scored = [&](std::vector<eval::WindowErrors>& dst, const std::vector<fusion::EpochOutput>& sol,
                          const eval::Trajectory& ref) -> Expected<void> {
      if (!reference) return add(dst, sol, ref);  // the run without outage covers every window
      auto we = window_errors(sol, ref, res.windows[k]);
      if (we && !we->t_since_s.empty()) {
        dst.push_back(std::move(*we));
        return {};
      }
      if (res.unscored_reason[k].empty()) {
        res.unscored_reason[k] =
            unscorable_reason(*reference, res.windows[k],
                              we ? std::string("no solution epoch inside the window matches the reference")
                                 : we.error().message);
      }
      eval::WindowErrors empty;
      empty.window = res.windows[k];
      dst.push_back(std::move(empty));
      return {};
    };
    const bool smoothed = res.has_smoothed && r.summary.smoothed;
    if (res.has_smoothed && !r.summary.smoothed) {
      spdlog::warn("window {}: smoother did not run ({}); smoothed figures use the forward solution", k + 1,
                   r.summary.smoother_message);
    }
    const auto& sol_s = smoothed ? r.smoothed : r.epochs;
    const eval::Trajectory& ref_f = reference ? *reference : nominal_fwd;
    const eval::Trajectory& ref_s = reference ? *reference : (res.has_smoothed ? nominal_smo : nominal_fwd);
    if (auto ok = add_scored(ef, r.epochs, ref_f); !ok) return ok.error();
    if (auto ok = add_scored(es, sol_s, ref_s); !ok) return ok.error();
    if (auto ok = add(ef_run, r.epochs, nominal_fwd); !ok) return ok.error();
    if (auto ok = add(es_run, sol_s, res.has_smoothed ? nominal_smo : nominal_fwd); !ok) return ok.error();
    // Satellites left per masked epoch.
    int mn = 1 << 30, mx = 0;
    double sum = 0.0;
    int n = 0;
    for (const auto& re : d.rover->epochs) {
      if (!res.windows[k].contains(re.time)) continue;
      int left = 0;
      if (a.keep_sats > 0) {
        auto it = plan->find(re.time.ns());
        left = it == plan->end() ? 0 : static_cast<int>(it->second.size());
      }
      mn = std::min(mn, left);
      mx = std::max(mx, left);
      sum += left;
      ++n;
    }
    res.sats_kept_min.push_back(n > 0 ? mn : 0);
    res.sats_kept_max.push_back(mx);
    res.sats_kept_mean.push_back(n > 0 ? sum / n : 0.0);
  }
  for (size_t k = 0; k < nw; ++k) {
    if (!res.unscored_reason[k].empty()) {
      spdlog::warn("outage window {} ({}): not scored: {}", k + 1, res.windows[k].start.to_string(),
                   res.unscored_reason[k]);
    }
  }
  res.forward = figures(ef);
  res.smoothed = figures(es);
  res.forward_vs_run = figures(ef_run);
  res.smoothed_vs_run = figures(es_run);

  // Outputs.
  std::error_code ec;
  std::filesystem::create_directories(a.out_dir, ec);
  if (ec) return make_error(a.out_dir + ": cannot create output folder: " + ec.message());
  const std::filesystem::path out(a.out_dir);
  std::string csv =
      "window,start_gps_week,start_gps_tow_s,duration_s,keep_sats,sats_left_min,sats_left_mean,sats_left_max,"
      "gnss_epochs_emptied,max_error_m,end_error_m,max_error_smoothed_m,end_error_smoothed_m,max_error_vs_run_m,"
      "end_error_vs_run_m,max_error_smoothed_vs_run_m,end_error_smoothed_vs_run_m,"
      "sigma_at_max_error_m,end_sigma_m,sigma_at_max_error_smoothed_m,end_sigma_smoothed_m,scored,unscored_reason\n";
  // Without a smoothed nominal run (smoother off, or re-initialized) the smoothed columns stay empty.
  const bool has_s = res.has_smoothed;
  for (size_t k = 0; k < nw; ++k) {
    const auto& f = res.forward.per_window[k];
    const auto& s = res.smoothed.per_window[k];
    const auto& fr = res.forward_vs_run.per_window[k];
    const auto& sr = res.smoothed_vs_run.per_window[k];
    csv += fmt::format("{},{},{:.3f},{:.3f},{},{},{:.2f},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", k + 1,
                       res.windows[k].start.week(), res.windows[k].start.tow_s(), res.windows[k].duration_s,
                       a.keep_sats, res.sats_kept_min[k], res.sats_kept_mean[k], res.sats_kept_max[k],
                       res.epochs_masked[k], fmt_opt(f.max_m, f.samples > 0), fmt_opt(f.end_m, f.samples > 0),
                       fmt_opt(s.max_m, has_s && s.samples > 0), fmt_opt(s.end_m, has_s && s.samples > 0),
                       fmt_opt(fr.max_m, fr.samples > 0), fmt_opt(fr.end_m, fr.samples > 0),
                       fmt_opt(sr.max_m, has_s && sr.samples > 0), fmt_opt(sr.end_m, has_s && sr.samples > 0),
                       fmt_opt(f.sigma_at_max_m, f.samples > 0), fmt_opt(f.end_sigma_m, f.samples > 0),
                       fmt_opt(s.sigma_at_max_m, has_s && s.samples > 0),
                       fmt_opt(s.end_sigma_m, has_s && s.samples > 0), res.unscored_reason[k].empty() ? 1 : 0,
                       csv_text(res.unscored_reason[k]));
  }
  if (auto ok = write_file_atomic((out / "outages.csv").string(), csv); !ok) return ok.error();
  if (a.write_runs) {
    for (size_t k = 0; k < nw; ++k) {
      const auto sub = out / fmt::format("window_{}", k + 1);
      std::filesystem::create_directories(sub, ec);
      if (ec) return make_error(sub.string() + ": cannot create: " + ec.message());
      const fusion::EngineResult& r = **runs[k];
      if (auto ok = write_solution_csv((sub / "solution.csv").string(), solution_rows(r.epochs)); !ok) return ok.error();
      if (r.summary.smoothed) {
        if (auto ok = write_solution_csv((sub / "smoothed.csv").string(), solution_rows(r.smoothed)); !ok) {
          return ok.error();
        }
      }
    }
  }

  // rms_vs_time.csv: DESIGN.md columns, then the smoothed ones (same bins: both come from the same windows).
  std::map<long, std::array<double, 4>> rows;  // bin -> rms_f, n_f, rms_s, n_s
  auto key = [](double t) { return std::lround(t); };
  for (size_t i = 0; i < res.forward.rms.t_since_s.size(); ++i) {
    rows[key(res.forward.rms.t_since_s[i])] = {res.forward.rms.rms_m[i],
                                               static_cast<double>(res.forward.rms.n_windows[i]), NAN, 0};
  }
  for (size_t i = 0; i < res.smoothed.rms.t_since_s.size(); ++i) {
    auto& r = rows.try_emplace(key(res.smoothed.rms.t_since_s[i]), std::array<double, 4>{NAN, 0, NAN, 0}).first->second;
    r[2] = res.smoothed.rms.rms_m[i];
    r[3] = static_cast<double>(res.smoothed.rms.n_windows[i]);
  }
  std::string rcsv = "t_since_outage_s,rms_horizontal_m,n_windows,rms_horizontal_smoothed_m,n_windows_smoothed\n";
  for (const auto& [t, r] : rows) {
    rcsv += fmt::format("{},{},{},{},{}\n", t, fmt_opt(r[0], true), static_cast<int>(r[1]),
                        fmt_opt(r[2], true), static_cast<int>(r[3]));
  }
  if (auto ok = write_file_atomic((out / "rms_vs_time.csv").string(), rcsv); !ok) return ok.error();

  if (a.plot) {
    PlotSpec p;
    p.title = fmt::format("{} x {:.0f} s outages, {} (error vs {})", nw, a.duration_s,
                          a.keep_sats == 0 ? std::string("full") : fmt::format("keep {} satellites", a.keep_sats),
                          res.against == "reference" ? "reference" : "run without outage");
    p.x_label = "time since outage start [s]";
    p.y_label = "horizontal error [m]";
    p.y_from_zero = true;
    for (size_t k = 0; k < ef.size(); ++k) {
      PlotSeries s;
      s.title = k == 0 ? "forward, each window" : "";
      s.x = ef[k].t_since_s;
      s.y = ef[k].horizontal_m;
      s.color = "#bbbbbb";
      s.width = 1.0;
      p.series.push_back(std::move(s));
    }
    PlotSeries f{"forward RMS across windows", PlotStyle::kLines, res.forward.rms.t_since_s, res.forward.rms.rms_m,
                 {}, {}, "#1f77b4", 2.5};
    p.series.push_back(f);
    if (res.has_smoothed) {
      PlotSeries s{"smoothed RMS across windows", PlotStyle::kLines, res.smoothed.rms.t_since_s, res.smoothed.rms.rms_m,
                   {}, {}, "#d62728", 2.5};
      p.series.push_back(s);
    }
    if (auto ok = write_plot_svg((out / "outage_rms.svg").string(), p); !ok) {
      spdlog::warn("outage_rms.svg not written: {}", ok.error().message);
    }
  }

  nlohmann::ordered_json j;
  j["windows"] = nw;
  j["duration_s"] = a.duration_s;
  j["keep_sats"] = a.keep_sats;
  j["max_error_m"] = res.forward.max_error_m;
  j["rms_at_end_m"] = res.forward.rms_at_end_m;
  j["max_rms_m"] = res.forward.max_rms_m;
  j["outage"] = a.keep_sats == 0 ? "full" : "partial";
  j["keep_by"] = a.keep_by == eval::KeepBy::kCn0 ? "cn0" : "elevation";
  j["against"] = res.against;
  j["windows_unscored"] = std::count_if(res.unscored_reason.begin(), res.unscored_reason.end(),
                                        [](const std::string& r) { return !r.empty(); });
  if (reference) j["reference"] = c.reference.file;
  if (res.has_smoothed) j["smoothed"] = figures_json(res.smoothed);
  j["vs_run_without_outage"] = {{"forward", figures_json(res.forward_vs_run)}};
  if (res.has_smoothed) j["vs_run_without_outage"]["smoothed"] = figures_json(res.smoothed_vs_run);
  nlohmann::ordered_json wl = nlohmann::json::array();
  for (size_t k = 0; k < nw; ++k) {
    const bool scored = res.unscored_reason[k].empty();
    wl.push_back({{"start_gps_week", res.windows[k].start.week()},
                  {"start_gps_tow_s", res.windows[k].start.tow_s()},
                  {"max_error_m", scored ? nlohmann::json(res.forward.per_window[k].max_m) : nlohmann::json()},
                  {"end_error_m", scored ? nlohmann::json(res.forward.per_window[k].end_m) : nlohmann::json()},
                  {"sats_left_mean", res.sats_kept_mean[k]}});
    // The forward filter's own horizontal 1σ beside its errors (absent when the solution carries no covariance).
    const auto& f = res.forward.per_window[k];
    if (std::isfinite(f.sigma_at_max_m)) wl.back()["sigma_at_max_error_m"] = f.sigma_at_max_m;
    if (std::isfinite(f.end_sigma_m)) wl.back()["end_sigma_m"] = f.end_sigma_m;
    wl.back()["scored"] = scored;
    if (!scored) wl.back()["unscored_reason"] = res.unscored_reason[k];
  }
  if (res.carrier) {
    // Re-fix after each window (docs/outage.md §1.1): null where the run was not fixed again before its end.
    auto seconds = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    std::vector<double> got;
    for (size_t k = 0; k < nw; ++k) {
      wl[k]["refix_s"] = seconds(res.refix_s[k]);
      wl[k]["nominal_fix_s"] = seconds(res.nominal_fix_s[k]);
      if (std::isfinite(res.refix_s[k])) got.push_back(res.refix_s[k]);
    }
    std::sort(got.begin(), got.end());
    j["carrier"] = {{"windows_refixed", got.size()},
                    {"refix_median_s", got.empty() ? nlohmann::json(nullptr)
                                                   : nlohmann::json(0.5 * (got[(got.size() - 1) / 2] + got[got.size() / 2]))},
                    {"refix_max_s", got.empty() ? nlohmann::json(nullptr) : nlohmann::json(got.back())}};
  }
  j["window_list"] = wl;
  j["config"] = c.source_file;
  j["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  if (auto ok = write_file_atomic((out / "summary.json").string(), j.dump(2) + "\n"); !ok) return ok.error();
  return res;
}

}  // namespace pednav::pipeline
