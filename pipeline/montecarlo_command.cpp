// SPDX-License-Identifier: BSD-2-Clause
// `pednav montecarlo` (pipeline/montecarlo_command.hpp).
#include "pipeline/montecarlo_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "eval/montecarlo.hpp"
#include "fusion/ambiguity.hpp"
#include "fusion/engine.hpp"
#include "io/atomic_file.hpp"
#include "io/config.hpp"
#include "io/log.hpp"
#include "io/plot.hpp"
#include "io/plot_figures.hpp"
#include "io/scenario_config.hpp"
#include "pipeline/montecarlo_runs.hpp"
#include "pipeline/run_command.hpp"
#include "pipeline/simulate_command.hpp"
#include "sim/gnss_sim.hpp"
#include "sim/simulator.hpp"

namespace pednav::pipeline {
namespace {

// Mode ins starts every run from the true position and heading; its P says so (1 cm, 0.1°: small, not zero).
constexpr double kTrueStartSigmaPosM = 0.01;
constexpr double kTrueStartSigmaYawRad = 0.1 * 3.14159265358979323846 / 180.0;
// A fixed antenna more than this far (horizontal) from the simulated antenna is a wrong fix (L1: a wrong integer
// moves it by ≥ 0.19 m along some direction; scripts/carrier_seeds uses the same threshold).
constexpr double kWrongFixHorizontalM = 0.10;

double yaw_n(const ins::NavState& x) {
  const Geodetic llh = geodetic_from_ecef(x.p_eb_e);
  return euler_from_R_n_b(R_e_n(llh.lat, llh.lon).transpose() * x.R_e_b()).z();
}

// The truth sample at an output epoch's time (the IMU-rate grid, GPST), or −1 when the epoch is off the grid.
long truth_index(const sim::Simulation& s, GpsTime t) {
  const auto& nav = s.truth.nav;
  const long i = std::lround((t - nav.front().t) * s.scenario.imu.rate_hz);
  return i < 0 || i >= static_cast<long>(nav.size()) || std::abs(nav[i].t - t) > 1e-6 ? -1 : i;
}

// Errors of one solution against the simulation truth (at the IMU rate, GPST on the sample grid).
std::vector<eval::McEpoch> errors(const sim::Simulation& s, const std::vector<fusion::EpochOutput>& sol) {
  std::vector<eval::McEpoch> out;
  const auto& nav = s.truth.nav;
  for (const auto& e : sol) {
    const long i = truth_index(s, e.t);
    if (i < 0) continue;
    eval::McEpoch m;
    m.t_s = e.t - s.scenario.start;
    m.distance_m = i < static_cast<long>(s.antenna.size()) ? s.antenna[i].route_m : 0.0;
    const Eigen::Vector3d enu = enu_from_ecef(e.nav.p_eb_e, nav[i].p_eb_e);
    m.err_ned_m = Eigen::Vector3d(enu.y(), enu.x(), -enu.z());
    // Symmetric, as the run file stores it (upper triangle): a run read back aggregates to the same bits.
    m.cov_ned_m2 = 0.5 * (e.cov_p_n + e.cov_p_n.transpose());
    m.err_yaw_rad = wrap_pi(yaw_n(e.nav) - yaw_n(nav[i]));
    m.var_yaw_rad2 = e.sd_yaw_rad * e.sd_yaw_rad;
    out.push_back(m);
  }
  return out;
}

// The forward solution's carrier figures at the GNSS epochs (docs/consistency.md §6): status, the antenna against the
// simulated antenna, its horizontal NEES where fixed.
eval::McCarrierRun carrier_figures(const sim::Simulation& s, const std::vector<fusion::EpochOutput>& sol) {
  eval::McCarrierRun c;
  std::set<long long> gnss_ms;
  for (const auto& ep : s.gnss.rover.epochs) gnss_ms.insert(std::llround((ep.time - s.scenario.start) * 1e3));
  double first_s = -1.0;
  for (const auto& e : sol) {
    const double t_s = e.t - s.scenario.start;
    if (!gnss_ms.count(std::llround(t_s * 1e3))) continue;
    const long i = truth_index(s, e.t);
    if (i < 0 || i >= static_cast<long>(s.antenna.size())) continue;
    if (first_s < 0.0) first_s = t_s;
    ++c.gnss_epochs;
    if (static_cast<fusion::SolutionStatus>(e.solution_status) != fusion::SolutionStatus::kFixed || !e.has_antenna) continue;
    if (c.fixed_epochs++ == 0) c.time_to_first_fix_s = t_s - first_s;
    const Eigen::Vector3d enu = enu_from_ecef(e.ant_p_e, s.antenna[i].p_e);
    const Eigen::Vector2d err_ne(enu.y(), enu.x());
    if (err_ne.norm() > kWrongFixHorizontalM) ++c.wrong_fixed_epochs;
    const Eigen::Matrix2d P = 0.5 * (e.cov_ant_p_n.topLeftCorner<2, 2>() + e.cov_ant_p_n.topLeftCorner<2, 2>().transpose());
    c.antenna_nees_sum += err_ne.dot(P.ldlt().solve(err_ne));
  }
  return c;
}

// Simulate and run one seed (thread-safe: in-memory simulation and engine, no RTKLIB).
RunRecord run_one(const io::ScenarioFile& file, const MontecarloArgs& mo, int index) {
  RunRecord r;
  r.index = index;
  const auto t0 = std::chrono::steady_clock::now();
  sim::Scenario sc = file.scenario;
  sc.seed = file.scenario.seed + mo.seed_offset + static_cast<uint64_t>(index);
  r.seed = sc.seed;
  auto s = sim::simulate(sc);
  if (!s) {
    r.message = s.error().message;
    return r;
  }
  const std::string mode = !mo.mode.empty() ? mo.mode : (s->has_gnss ? "tc" : "ins");
  io::RunConfig c;  // `pednav run` defaults, as in the configuration `pednav simulate` writes
  c.mode = mode;
  c.imu.spec = sc.imu.spec;
  c.zupt.form = mo.zupt_form;
  c.smoother_enabled = mo.smoother;
  if (mo.no_scale_states) c.scale_factors.states = false;
  if (mo.gauss_markov_bias) c.bias.model = "gauss_markov";
  // The simulated sensors' own models where the flags ask for them (what config_datasheet.yaml of pednav simulate
  // has): receiver weights (docs/consistency.md §3.8), walker lever arm (docs/fusion.md §14), the gyro's
  // g-sensitivity σ (its 9 consider states, docs/error_state.md §5), code multipath σ/τ (docs/consistency.md §3).
  pipeline::DataSheetParts parts;
  parts.receiver_weights = mo.receiver_weights;
  parts.lever_arm = mo.scenario_lever_arm;
  parts.g_sensitivity = mo.g_sensitivity_states;
  parts.multipath = mo.multipath_states;
  pipeline::apply_data_sheet(sc, parts, c);
  if (!std::isnan(mo.elevation_weight)) c.gnss.elevation_weight = mo.elevation_weight;
  if (mo.scale_bias_compensation) c.scale_factors.bias_compensation = *mo.scale_bias_compensation;
  fusion::EngineOptions o = pipeline::engine_options(c);
  if (mo.smoother_eiv_regression) o.smoother_eiv_regression = *mo.smoother_eiv_regression;
  if (mo.scale_states || mo.accel_scale_states) o.estimate_scale_factors = true;
  if (mo.scale_states) o.estimate_gyro_scale_factors = true;  // both blocks (the tc default)
  if (mo.accel_scale_states) o.estimate_gyro_scale_factors = false;
  if (mo.bias_random_walk) o.bias_random_walk = true;
  o.repair_saturation = mo.saturation_repair;
  if (mo.no_doppler) o.use_doppler = false;
  if (mo.foot_antenna_velocity) o.antenna_velocity_model = fusion::AntennaVelocityModel::kFoot;
  if (mo.white_code) o.multipath_sigma_m = 0.0;
  if (mo.carrier) {  // what load_run_inputs does for gnss.carrier: on (docs/carrier.md §8, §10)
    if (!sc.gnss.carrier_phase) {
      r.message = "--carrier needs a scenario with gnss.carrier_phase: true";
      return r;
    }
    o.carrier = true;
    o.antenna_state = true;
  }
  o.zupt_updates = mo.zupt_updates;
  o.step_velocity.enabled = mo.step_velocity;
  o.step_velocity.leg_length_m = mo.leg_length_m;
  fusion::EngineInputs in;
  in.imu = &s->imu;
  if (mode == "tc") {
    if (!s->has_gnss) {
      r.message = "mode tc needs a scenario with gnss.enabled";
      return r;
    }
    o.base_position_e = s->gnss.p_base_e;
    in.nav = &s->nav;
    in.rover = &s->gnss.rover.epochs;
    in.base = &s->gnss.base.epochs;
  } else {
    // INS/ZUPT only: start from the true position and heading (seed 000: errors relative to a known start).
    const ins::NavState& t0n = s->truth.nav.front();
    o.initial_position_e = t0n.p_eb_e;
    o.initial_yaw_rad = yaw_n(t0n);
    // ... and say so in P: the configured 5 m / 10° are for a typed-in start, and would make every σ ratio and
    // NEES of an ins run measure the initial uncertainty instead of the drift (docs/consistency.md §1).
    o.initial_sigma_pos_m = kTrueStartSigmaPosM;
    o.initial_sigma_yaw_rad = kTrueStartSigmaYawRad;
  }
  auto res = fusion::run_forward(in, o);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!res) {
    r.message = res.error().message;
    return r;
  }
  r.ok = true;
  r.distance_m = s->antenna.empty() ? 0.0 : s->antenna.back().route_m;
  r.run.forward = errors(*s, res->epochs);
  r.run.smoothed = errors(*s, res->smoothed);
  if (mo.carrier) r.run.carrier = carrier_figures(*s, res->epochs);
  return r;
}

double horizontal_rms(const std::vector<eval::McEpoch>& ep) {
  if (ep.empty()) return std::nan("");
  double s = 0;
  for (const auto& e : ep) s += e.err_ned_m.head<2>().squaredNorm();
  return std::sqrt(s / static_cast<double>(ep.size()));
}

nlohmann::json summary_json(const eval::McSummary& m) {
  return {{"epochs", m.epochs},
          {"nees_in_band_fraction", m.nees_in_band_fraction},
          {"nees_above_band_fraction", m.nees_above_band_fraction},
          {"nees_below_band_fraction", m.nees_below_band_fraction},
          {"nees_yaw_in_band_fraction", m.nees_yaw_in_band_fraction},
          {"mean_nees_horizontal", m.mean_nees_horizontal},
          {"sigma_ratio_horizontal", m.sigma_ratio_horizontal},
          {"sigma_ratio_yaw", m.sigma_ratio_yaw},
          {"sigma_ratio_horizontal_pooled", m.sigma_ratio_horizontal_pooled},
          {"sigma_ratio_yaw_pooled", m.sigma_ratio_yaw_pooled},
          {"inside_3sigma_fraction", m.inside_3sigma_fraction},
          {"rms_horizontal_m", m.rms_horizontal_m}};
}

void nees_rows(std::ostringstream& o, const char* sol, const std::vector<eval::McEpochStats>& st) {
  for (const auto& e : st) {
    o << sol << ',' << e.t_s << ',' << e.runs << ',' << e.distance_m;
    for (int i = 0; i < 3; ++i) o << ',' << e.mean_err_ned_m(i);
    for (int i = 0; i < 3; ++i) o << ',' << e.sample_sd_ned_m(i);
    for (int i = 0; i < 3; ++i) o << ',' << e.filter_sd_ned_m(i);
    o << ',' << e.mean_err_yaw_rad * kRadToDeg << ',' << e.sample_sd_yaw_rad * kRadToDeg << ','
      << e.filter_sd_yaw_rad * kRadToDeg << ',' << e.rms_horizontal_m << ',' << e.nees_horizontal << ','
      << e.nees_lo_2dof << ',' << e.nees_hi_2dof << ',' << e.nees_yaw << ',' << e.nees_lo_1dof << ','
      << e.nees_hi_1dof << ',' << e.inside_3sigma_fraction << '\n';
  }
}

// runs.csv, nees.csv, summary.json and the figures from every run's record (one process, or merged shards).
Expected<void> aggregate(const MontecarloArgs& mo, const std::string& scenario_name, const std::vector<RunRecord>& records,
                         size_t done_now, int jobs, std::chrono::steady_clock::time_point t_start) {
  // runs.csv
  std::vector<eval::McRun> ok_runs;
  std::ostringstream rc;
  rc.precision(8);
  rc << "run,seed,ok,wall_s,distance_m,epochs,forward_rms_horizontal_m,smoothed_rms_horizontal_m,"
        "forward_final_horizontal_m,message";
  if (mo.carrier) rc << ",gnss_epochs,fixed_epochs,wrong_fixed_epochs,time_to_first_fix_s";
  rc << "\n";
  double run_wall_sum = 0;
  for (const auto& r : records) {
    run_wall_sum += r.wall_s;
    const auto& f = r.run.forward;
    std::string msg = r.message;
    std::replace(msg.begin(), msg.end(), ',', ';');
    rc << r.index << ',' << r.seed << ',' << r.ok << ',' << r.wall_s << ',' << r.distance_m << ',' << f.size() << ','
       << horizontal_rms(f) << ',' << horizontal_rms(r.run.smoothed) << ','
       << (f.empty() ? std::nan("") : f.back().err_ned_m.head<2>().norm()) << ",\"" << msg << "\"";
    const eval::McCarrierRun& c = r.run.carrier;
    if (mo.carrier) rc << ',' << c.gnss_epochs << ',' << c.fixed_epochs << ',' << c.wrong_fixed_epochs << ',' << c.time_to_first_fix_s;
    rc << '\n';
    if (r.ok) ok_runs.push_back(r.run);
    else spdlog::warn("montecarlo: run {} (seed {}) failed: {}", r.index, r.seed, r.message);
  }
  if (ok_runs.size() < 2) {
    return make_error(fmt::format("montecarlo: {} successful runs; at least 2 are needed for statistics", ok_runs.size()));
  }
  const int n_ok = static_cast<int>(ok_runs.size());
  // Epochs present in at least 90 % of the successful runs (start/end epochs differ slightly between seeds).
  const int min_runs = std::max(2, static_cast<int>(std::ceil(0.9 * n_ok)));
  const auto fwd = eval::aggregate_epochs(ok_runs, false, min_runs);
  const auto smo = eval::aggregate_epochs(ok_runs, true, min_runs);
  std::ostringstream nc;
  nc.precision(8);
  nc << "solution,t_s,runs,distance_m,mean_err_n_m,mean_err_e_m,mean_err_d_m,sample_sd_n_m,sample_sd_e_m,"
        "sample_sd_d_m,filter_sd_n_m,filter_sd_e_m,filter_sd_d_m,mean_err_yaw_deg,sample_sd_yaw_deg,filter_sd_yaw_deg,"
        "rms_horizontal_m,nees_horizontal,nees_lo_2dof,nees_hi_2dof,nees_yaw,nees_lo_1dof,nees_hi_1dof,"
        "inside_3sigma_fraction\n";
  nees_rows(nc, "forward", fwd);
  nees_rows(nc, "smoothed", smo);
  const eval::McSummary sf = eval::summarize(fwd, n_ok, mo.summary_from_s);
  const eval::McSummary ss = eval::summarize(smo, n_ok, mo.summary_from_s);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  nlohmann::json j;
  j["scenario"] = scenario_name;
  j["runs"] = n_ok;
  j["runs_requested"] = mo.runs;
  j["runs_failed"] = mo.runs - n_ok;
  j["runs_done_now"] = done_now;
  j["jobs"] = jobs;
  j["nees_in_band_fraction_forward"] = sf.nees_in_band_fraction;
  // No smoothed epochs (--no-smoother, or a re-initialized run): null, not 0.
  const bool have_smoothed = ss.epochs > 0;
  auto smoothed_value = [&](double v) { return have_smoothed ? nlohmann::json(v) : nlohmann::json(nullptr); };
  j["nees_in_band_fraction_smoothed"] = smoothed_value(ss.nees_in_band_fraction);
  j["sigma_ratio_horizontal"] = sf.sigma_ratio_horizontal;
  j["sigma_ratio_yaw"] = sf.sigma_ratio_yaw;
  j["sigma_ratio_horizontal_smoothed"] = smoothed_value(ss.sigma_ratio_horizontal);
  j["sigma_ratio_yaw_smoothed"] = smoothed_value(ss.sigma_ratio_yaw);
  j["wall_s"] = wall;
  j["run_wall_s_sum"] = run_wall_sum;
  j["nees_band_probability"] = 0.95;
  j["min_runs_per_epoch"] = min_runs;
  j["forward"] = summary_json(sf);
  j["smoothed"] = have_smoothed ? summary_json(ss) : nlohmann::json(nullptr);
  // The band test by time window (docs/consistency.md §1, §3.13): where the in-band share is lost.
  auto windows_json = [&](const std::vector<eval::McEpochStats>& ep) {
    nlohmann::json a = nlohmann::json::array();
    for (const eval::McWindowBand& w : eval::window_bands(ep, mo.window_s)) {
      a.push_back({{"from_s", w.from_s}, {"to_s", w.to_s}, {"epochs", w.epochs},
                   {"nees_in_band_fraction", w.nees_in_band_fraction},
                   {"mean_nees_horizontal", w.mean_nees_horizontal}});
    }
    return a;
  };
  j["window_s"] = mo.window_s;
  j["windows_forward"] = windows_json(fwd);
  j["windows_smoothed"] = have_smoothed ? windows_json(smo) : nlohmann::json(nullptr);
  std::string carrier_text;
  if (mo.carrier) {  // docs/consistency.md §6
    const eval::McCarrierSummary k = eval::summarize_carrier(ok_runs);
    auto seconds = [](double v) { return v < 0.0 ? nlohmann::json(nullptr) : nlohmann::json(v); };
    j["carrier"] = {{"gnss_epochs", k.gnss_epochs},
                    {"fixed_epochs", k.fixed_epochs},
                    {"fix_rate_pct", 100.0 * k.fix_rate},
                    {"wrong_fixed_epochs", k.wrong_fixed_epochs},
                    {"wrong_fix_rate_pct", 100.0 * k.wrong_fix_rate},
                    {"wrong_fix_horizontal_m", kWrongFixHorizontalM},
                    {"runs_with_fix", k.runs_with_fix},
                    {"runs_with_wrong_fix", k.runs_with_wrong_fix},
                    {"mean_antenna_nees_fixed", k.fixed_epochs > 0 ? nlohmann::json(k.mean_antenna_nees_fixed) : nullptr},
                    {"median_time_to_first_fix_s", seconds(k.median_time_to_first_fix_s)},
                    {"max_time_to_first_fix_s", seconds(k.max_time_to_first_fix_s)}};
    carrier_text = fmt::format("; carrier: {:.1f} % of {} GNSS epochs fixed, {} wrong ({:.2f} %) in {} of {} runs, "
                               "fixed antenna NEES {:.2f}",
                               100.0 * k.fix_rate, k.gnss_epochs, k.wrong_fixed_epochs, 100.0 * k.wrong_fix_rate,
                               k.runs_with_wrong_fix, k.runs, k.mean_antenna_nees_fixed);
  }
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"runs.csv", rc.str()},
                                   {"nees.csv", nc.str()},
                                   {"summary.json", j.dump(2) + "\n"}}) {
    if (auto w = io::write_file_atomic((std::filesystem::path(mo.out_dir) / name).string(), text); !w) return w.error();
  }
  if (mo.plots) {  // seed 000 Figs. 4-6 (gnuplot; a missing gnuplot costs the figures, not the run)
    const std::string what = fmt::format("{}, {} runs", scenario_name, n_ok);
    const std::vector<eval::McEpochStats> none;
    const auto& smo_or_none = have_smoothed ? smo : none;
    for (const auto& [name, spec] : std::vector<std::pair<std::string, io::PlotSpec>>{
             {"nees.svg",
              io::montecarlo_nees_plot(fmt::format("{}: average horizontal NEES (in band: forward {:.1f} %{})", what,
                                                   100.0 * sf.nees_in_band_fraction,
                                                   have_smoothed ? fmt::format(", smoothed {:.1f} %",
                                                                               100.0 * ss.nees_in_band_fraction)
                                                                 : std::string()),
                                       fwd, smo_or_none)},
             {"sigma.svg", io::montecarlo_sigma_plot(what + ": forward position sigma, sample vs filter", fwd, false)},
             {"sigma_yaw.svg", io::montecarlo_sigma_plot(what + ": forward yaw sigma, sample vs filter", fwd, true)},
             {"error_vs_distance.svg",
              io::montecarlo_distance_plot(what + ": RMS horizontal error vs distance", fwd, smo_or_none)}}) {
      if (auto w = io::write_plot_svg((std::filesystem::path(mo.out_dir) / name).string(), spec); !w) {
        spdlog::warn("montecarlo: {} not written: {}", name, w.error().message);
      }
    }
  }
  const std::string smoothed_text =
      have_smoothed ? fmt::format("NEES in band {:.1f} %, sigma ratio horizontal {:.3f} yaw {:.3f}, RMS {:.2f} m",
                                  100.0 * ss.nees_in_band_fraction, ss.sigma_ratio_horizontal, ss.sigma_ratio_yaw,
                                  ss.rms_horizontal_m)
                    : std::string("none");
  spdlog::info("montecarlo: {} runs ({} failed) in {:.1f} s on {} threads; forward: NEES in band {:.1f} % of {} "
               "epochs, sigma ratio horizontal {:.3f} yaw {:.3f}, RMS {:.2f} m; smoothed: {}{} -> {}",
               n_ok, mo.runs - n_ok, wall, jobs, 100.0 * sf.nees_in_band_fraction, sf.epochs,
               sf.sigma_ratio_horizontal, sf.sigma_ratio_yaw, sf.rms_horizontal_m, smoothed_text, carrier_text,
               mo.out_dir);
  return {};
}

// What a shard's runs depend on, as JSON: the scenario text and every option that changes a run or the aggregation
// (not the output folder, the thread count, the figures or the shard itself).
nlohmann::ordered_json study_json(const MontecarloArgs& a) {
  nlohmann::ordered_json j;
  j["runs"] = a.runs;
  j["mode"] = a.mode;
  j["zupt_form"] = a.zupt_form;
  j["smoother"] = a.smoother;
  j["seed_offset"] = a.seed_offset;
  j["summary_from_s"] = a.summary_from_s;
  j["zupt_updates"] = a.zupt_updates;
  j["step_velocity"] = a.step_velocity;
  j["leg_length_m"] = a.leg_length_m;
  j["multipath_states"] = a.multipath_states;
  j["white_code"] = a.white_code;
  j["scale_states"] = a.scale_states;
  j["accel_scale_states"] = a.accel_scale_states;
  j["bias_random_walk"] = a.bias_random_walk;
  j["no_scale_states"] = a.no_scale_states;
  j["gauss_markov_bias"] = a.gauss_markov_bias;
  j["saturation_repair"] = a.saturation_repair;
  j["no_doppler"] = a.no_doppler;
  j["foot_antenna_velocity"] = a.foot_antenna_velocity;
  j["scale_bias_compensation"] = a.scale_bias_compensation ? nlohmann::json(*a.scale_bias_compensation) : nullptr;
  j["smoother_eiv_regression"] = a.smoother_eiv_regression ? nlohmann::json(*a.smoother_eiv_regression) : nullptr;
  j["elevation_weight"] = std::isnan(a.elevation_weight) ? nlohmann::json(nullptr) : nlohmann::json(a.elevation_weight);
  j["scenario_lever_arm"] = a.scenario_lever_arm;
  j["g_sensitivity_states"] = a.g_sensitivity_states;
  j["window_s"] = a.window_s;
  j["receiver_weights"] = a.receiver_weights;
  if (a.carrier) j["carrier"] = true;  // absent when off: the fingerprints of earlier studies stay valid
  return j;
}

// FNV-1a 64-bit of a text (a stable fingerprint on every platform; not a cryptographic hash).
std::string fnv1a(const std::string& text) {
  uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  return fmt::format("{:016x}", h);
}

std::string study_fingerprint(const MontecarloArgs& a) {
  std::ifstream in(a.scenario_path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return fnv1a(text.str() + "\n" + study_json(a).dump());
}

// OUT/shard.json: which shard of which study, the seeds it ran, and how they went.
Expected<void> write_shard(const MontecarloArgs& mo, const io::ScenarioFile& file, const std::vector<int>& mine,
                           const std::vector<RunRecord>& records, size_t done_now,
                           std::chrono::steady_clock::time_point t_start) {
  int ok = 0;
  for (int i : mine) ok += records[i].ok;
  nlohmann::ordered_json j;
  j["study_fingerprint"] = study_fingerprint(mo);
  j["scenario"] = file.scenario.name;
  j["shard"] = mo.shard_index;
  j["shards"] = mo.shard_count;
  j["study"] = study_json(mo);
  j["run_indices"] = mine;
  j["runs_ok"] = ok;
  j["runs_failed"] = static_cast<int>(mine.size()) - ok;
  j["runs_done_now"] = done_now;
  j["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  if (auto w = io::write_file_atomic((std::filesystem::path(mo.out_dir) / "shard.json").string(), j.dump(2) + "\n"); !w)
    return w.error();
  spdlog::info("montecarlo: shard {}/{}: {} runs ({} failed) -> {} (merge with pednav montecarlo-merge)", mo.shard_index,
               mo.shard_count, mine.size(), mine.size() - ok, mo.out_dir);
  return {};
}

}  // namespace

Expected<void> run_montecarlo_command(const MontecarloArgs& mo) {
  if (mo.shard_count < 1 || mo.shard_index < 1 || mo.shard_index > mo.shard_count) {
    return make_error(fmt::format("--shard {}/{}: expected K/N with 1 <= K <= N", mo.shard_index, mo.shard_count));
  }
  const auto t_start = std::chrono::steady_clock::now();
  auto file = io::load_scenario(mo.scenario_path);
  if (!file) return file.error();
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(mo.out_dir) / "runs", ec);
  if (ec) return make_error(fmt::format("{}: cannot create the output folder: {}", mo.out_dir, ec.message()));
  // This process's share of the seeds (all of them unless --shard K/N: runs i with i mod N = K - 1).
  std::vector<int> mine;
  for (int i = 0; i < mo.runs; ++i) {
    if (i % mo.shard_count == mo.shard_index - 1) mine.push_back(i);
  }
  // Resume: runs whose file exists are read, not redone.
  std::vector<RunRecord> records(mo.runs);
  std::vector<int> todo;
  for (int i : mine) {
    const std::string p = run_file(mo.out_dir, i);
    if (std::filesystem::exists(p)) {
      auto r = read_run(p);
      if (!r) return make_error(r.error().message + " (delete it to redo that run)");
      records[i] = std::move(*r);
    } else {
      todo.push_back(i);
    }
  }
  if (todo.size() < mine.size()) {
    spdlog::info("montecarlo: {} of {} runs already done in {}, {} to run", mine.size() - todo.size(), mine.size(),
                 mo.out_dir, todo.size());
  }
  const int jobs = std::max(1, mo.jobs > 0 ? mo.jobs : static_cast<int>(std::thread::hardware_concurrency()));
  std::atomic<size_t> next{0};
  std::mutex mu;
  std::string write_error;
  io::Progress progress("montecarlo", static_cast<int64_t>(todo.size()), io::progress_enabled());
  int64_t done = 0;
  auto worker = [&] {
    for (;;) {
      const size_t k = next++;
      if (k >= todo.size()) return;
      RunRecord r = run_one(*file, mo, todo[k]);
      const auto w = write_run(run_file(mo.out_dir, r.index), r);
      std::lock_guard<std::mutex> lock(mu);
      if (!w && write_error.empty()) write_error = w.error().message;
      records[r.index] = std::move(r);
      progress.update(++done);
    }
  };
  std::vector<std::thread> threads;
  for (int j = 0; j < std::min<int>(jobs, static_cast<int>(todo.size())); ++j) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  progress.finish();
  if (!write_error.empty()) return make_error(write_error);

  if (mo.shard_count > 1) return write_shard(mo, *file, mine, records, todo.size(), t_start);
  return aggregate(mo, file->scenario.name, records, todo.size(), jobs, t_start);
}

}  // namespace pednav::pipeline

namespace pednav::pipeline {

Expected<void> run_montecarlo_merge(const std::string& out_dir, const std::vector<std::string>& shard_dirs, bool plots) {
  const auto t_start = std::chrono::steady_clock::now();
  if (shard_dirs.empty()) return make_error("montecarlo-merge: no shard folders given");
  std::string fingerprint, scenario;
  int shards = 0, runs = 0;
  MontecarloArgs mo;
  std::map<int, std::string> shard_dir;  // shard number -> folder
  for (const auto& d : shard_dirs) {
    const std::string path = (std::filesystem::path(d) / "shard.json").string();
    std::ifstream in(path);
    if (!in) return make_error(path + ": cannot read (not the output folder of pednav montecarlo --shard K/N?)");
    const auto j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.contains("study_fingerprint") || !j.contains("shard") || !j.contains("study"))
      return make_error(path + ": not a shard manifest (study_fingerprint, shard, study expected)");
    if (fingerprint.empty()) {
      fingerprint = j["study_fingerprint"];
      scenario = j.value("scenario", "");
      shards = j["shards"];
      runs = j["study"]["runs"];
      mo.runs = runs;
      mo.summary_from_s = j["study"]["summary_from_s"];
      mo.window_s = j["study"]["window_s"];
      mo.carrier = j["study"].value("carrier", false);
    } else if (j["study_fingerprint"] != fingerprint || j["shards"] != shards) {
      return make_error(fmt::format("{}: shard of a different study (scenario text, options or shard count differ from "
                                    "{})", path, shard_dirs.front()));
    }
    const int k = j["shard"];
    if (auto [it, fresh] = shard_dir.emplace(k, d); !fresh)
      return make_error(fmt::format("shard {}/{} given twice: {} and {}", k, shards, it->second, d));
  }
  std::string missing;
  for (int k = 1; k <= shards; ++k) {
    if (!shard_dir.count(k)) missing += (missing.empty() ? "" : ", ") + std::to_string(k);
  }
  if (!missing.empty()) return make_error(fmt::format("missing shards {} of {}", missing, shards));
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(out_dir) / "runs", ec);
  if (ec) return make_error(fmt::format("{}: cannot create the output folder: {}", out_dir, ec.message()));
  std::vector<RunRecord> records(runs);
  for (int i = 0; i < runs; ++i) {
    const std::string from = run_file(shard_dir.at(i % shards + 1), i);
    auto r = read_run(from);
    if (!r) return make_error(r.error().message + " (shard " + std::to_string(i % shards + 1) + " incomplete?)");
    std::ifstream src(from, std::ios::binary);
    std::ostringstream text;
    text << src.rdbuf();
    if (auto w = io::write_file_atomic(run_file(out_dir, i), text.str()); !w) return w.error();
    records[i] = std::move(*r);
  }
  mo.out_dir = out_dir;
  mo.plots = plots;
  return aggregate(mo, scenario, records, 0, 1, t_start);
}

}  // namespace pednav::pipeline
