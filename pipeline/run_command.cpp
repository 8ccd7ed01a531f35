// SPDX-License-Identifier: BSD-2-Clause
#include "pipeline/run_command.hpp"
#include "pipeline/run_summary.hpp"
#include "pipeline/run_warnings.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "eval/statistics.hpp"
#include "eval/trajectory.hpp"
#include "gnss/rtklib/rinex.hpp"
#include "io/atomic_file.hpp"
#include "io/residuals_writer.hpp"
#include "pipeline/compare_command.hpp"
#include "pipeline/reference_evaluation.hpp"
#include "io/hmm_model_io.hpp"
#include "io/imu_csv.hpp"
#include "io/solution_writer.hpp"
#include "io/trajectory_io.hpp"

namespace pednav::pipeline {

using namespace pednav::io;  // the readers, writers and configuration this use case drives
namespace {

gnss::System system_of(const std::string& letter) {
  if (letter == "R") return gnss::System::kGlonass;
  if (letter == "E") return gnss::System::kGalileo;
  if (letter == "C") return gnss::System::kBeidou;
  if (letter == "J") return gnss::System::kQzss;
  return gnss::System::kGps;
}


}  // namespace

SolutionRow solution_row(const fusion::EpochOutput& e) {
  SolutionRow r;
  r.time = e.t;
  r.p_e = e.nav.p_eb_e;
  const Geodetic llh = geodetic_from_ecef(e.nav.p_eb_e);
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  r.v_n = Ren.transpose() * e.nav.v_eb_e;
  r.rpy_deg = euler_from_R_n_b(Ren.transpose() * e.nav.R_e_b()) * kRadToDeg;
  r.cov_p_n = e.cov_p_n;
  r.sd_yaw_deg = e.sd_yaw_rad * kRadToDeg;
  r.n_sats_used = e.n_sats_used;
  r.n_sats_rejected = e.n_sats_rejected;
  r.zupt = e.zupt;
  r.pos_quality = e.n_sats_used > 0 ? 4 : 5;
  if (e.solution_status != 0) {  // with carrier (docs/carrier.md §6)
    const auto st = static_cast<fusion::SolutionStatus>(e.solution_status);
    r.solution_status = fusion::solution_status_name(st);
    r.pos_quality = fusion::pos_quality(st);
    r.n_fixed_ambiguities = e.n_fixed_ambiguities;
    r.ar_ratio = e.ar_ratio;
  }
  return r;
}

fusion::EngineOptions engine_options(const RunConfig& c) {
  fusion::EngineOptions o;
  o.mode = c.mode == "ins" ? fusion::Mode::kInsOnly : fusion::Mode::kTightlyCoupled;
  o.mechanization_rate_hz = c.mechanization_rate_hz;
  o.spec = c.imu.spec;
  o.zupt.detector = c.zupt.detector;
  o.zupt.mv_window_s = c.zupt.mv_window_s;
  o.zupt.mv_threshold_mps2 = c.zupt.mv_threshold_mps2;
  o.zupt.mv_gyro_threshold_radps = c.zupt.mv_gyro_threshold_radps;
  o.zupt.min_time_since_step_s = c.zupt.min_time_since_step_s;
  o.zupt.shoe_window_s = c.zupt.shoe_window_s;
  o.zupt.shoe_sigma_accel_mps2 = c.zupt.shoe_sigma_accel_mps2;
  o.zupt.shoe_sigma_gyro_radps = c.zupt.shoe_sigma_gyro_radps;
  o.zupt.shoe_threshold = c.zupt.shoe_threshold;
  o.zupt.min_stance_s = c.zupt.min_stance_s;
  o.zupt = zupt_detector_options(c.zupt);  // all detector keys incl. ARE/MAG/HMM (io/hmm_model_io.cpp)
  o.zupt_form = c.zupt.form == "F" ? fusion::ZuptForm::kFull : fusion::ZuptForm::kDynamic;
  o.step_velocity = c.step_velocity;
  o.zupt_updates = c.zupt.updates;
  o.zupt_sigma_mps = c.zupt.sigma_mps;
  o.zupt_edge_s = c.zupt.edge_s;
  o.zaru = c.zupt.zaru;
  o.zaru_sigma_radps = c.zupt.zaru_sigma_radps;
  o.zaru_gate_probability = c.zupt.zaru_gate_probability;
  o.initial_position_e = c.initial.position_e;
  o.initial_yaw_rad = c.initial.yaw_rad;
  o.heading_from_magnetometer = c.initial.heading_from_magnetometer;
  o.magnetic_declination_rad = c.initial.declination_rad;
  o.heading_init_distance_m = c.initial.heading_init_distance_m;
  o.initial_sigma_pos_m = c.initial.sigma_position_m;
  o.initial_sigma_vel_mps = c.initial.sigma_velocity_mps;
  o.initial_sigma_tilt_rad = c.initial.sigma_tilt_rad;
  o.initial_sigma_yaw_rad = c.initial.sigma_yaw_rad;
  o.systems.clear();
  for (const auto& s : c.gnss.systems) o.systems.push_back(system_of(s));
  o.elevation_mask_rad = c.gnss.elevation_mask_rad;
  o.min_cn0_dbhz = c.gnss.min_cn0_dbhz;
  o.weights.code_sigma_zenith_m = c.gnss.code_sigma_zenith_m;
  o.weights.doppler_sigma_zenith_mps = c.gnss.doppler_sigma_zenith_mps;
  o.weights.cn0_ref_dbhz = c.gnss.cn0_ref_dbhz;
  o.weights.glonass_code_factor = c.gnss.glonass_code_factor;
  o.weights.elevation_weight = c.gnss.elevation_weight;
  o.weights.code_squaring_loss = c.gnss.code_squaring_loss;
  o.use_doppler = c.gnss.use_doppler;
  o.max_base_age_s = c.gnss.max_base_age_s;
  o.lever_arm_n_m = c.antenna.lever_arm_ned_m;
  o.lever_arm_heading_m = c.antenna.lever_arm_heading_m;
  o.antenna_sigma_horizontal_m = c.antenna.sigma_horizontal_m;
  o.antenna_sigma_vertical_m = c.antenna.sigma_vertical_m;
  o.antenna_velocity_sigma_horizontal_mps = c.antenna.velocity_sigma_horizontal_mps;
  o.antenna_velocity_sigma_vertical_mps = c.antenna.velocity_sigma_vertical_mps;
  o.antenna_velocity_model = c.antenna.velocity_model == "foot" ? fusion::AntennaVelocityModel::kFoot
                                                                : fusion::AntennaVelocityModel::kStrideAverage;
  o.antenna_stride_velocity_sigma_horizontal_mps = c.antenna.stride_velocity_sigma_horizontal_mps;
  o.antenna_stride_velocity_sigma_vertical_mps = c.antenna.stride_velocity_sigma_vertical_mps;
  o.antenna_stance_sigma_horizontal_m = c.antenna.stance_sigma_horizontal_m;
  o.antenna_stance_sigma_vertical_m = c.antenna.stance_sigma_vertical_m;
  o.clock_psd_m2_per_s = c.clock.psd_m2_per_s;
  o.drift_psd_m2_per_s3 = c.clock.drift_psd_m2_per_s3;
  o.clock_jump_threshold_m = c.clock.jump_threshold_m;
  o.fault_probability = c.fault_rejection_probability;
  o.fault_window_epochs = c.fault_rejection_window_epochs;
  o.output_rate_hz = c.output.rate_hz;
  o.smoother_enabled = c.smoother_enabled;
  o.multipath_sigma_m = c.multipath.states ? c.multipath.sigma_m : 0.0;
  o.multipath_tau_s = c.multipath.tau_s;
  o.multipath_cn0_ref_dbhz = c.multipath.cn0_ref_dbhz;
  o.multipath_slots = c.multipath.slots;
  o.multipath_reset_gap_s = c.multipath.reset_gap_s;
  // Carrier phase: decided in load_run_inputs from the configuration and the data (gnss.carrier auto|on|off).
  o.carrier_sigma_zenith_m = c.gnss.carrier_sigma_zenith_m;
  o.carrier_base_age_sigma_mps = c.gnss.carrier_base_age_sigma_mps;
  o.ambiguity = ambiguity_options(c.gnss);
  // The tight coupling holds every validated fix: its own, stricter ratio threshold (docs/carrier.md §8).
  o.ambiguity.ratio_threshold = c.gnss.ambiguity.tc_ratio_threshold;
  o.antenna_accel_sigma_horizontal_mps2 = c.gnss.rtk_accel_sigma_horizontal_mps2;  // the RTK antenna's (eq. 10.1)
  o.antenna_accel_sigma_vertical_mps2 = c.gnss.rtk_accel_sigma_vertical_mps2;
  const ImuErrorModelChoice m = imu_error_model_choice(c);
  o.estimate_scale_factors = m.scale_states;
  o.estimate_gyro_scale_factors = m.gyro_scale_states;
  o.scale_bias_compensation = c.scale_factors.bias_compensation;
  o.bias_random_walk = m.bias_random_walk;
  o.repair_saturation = c.saturation.repair;
  return o;
}

fusion::EngineInputs RunInputs::engine_inputs() const {
  fusion::EngineInputs in;
  in.imu = &imu.samples;
  if (!imu.stance.empty()) in.stance_labels = &imu.stance;
  if (!imu.mag_b.empty()) in.mag_b = &imu.mag_b;
  if (rover) in.rover = &rover->epochs;
  if (nav) in.nav = &*nav;
  if (base) in.base = &base->epochs;
  return in;
}

std::vector<std::string> run_config_problems(const RunConfig& c) {
  std::vector<std::string> p;
  if (c.mode != "gnss") {
    if (!c.imu.has_format) p.push_back("imu.format: required for pednav run (a preset name or a column map)");
    for (const auto& f : c.imu.format.problems()) p.push_back("imu.format." + f);
    if (c.imu.has_format && c.initial.heading_from_magnetometer && c.imu.format.mag_columns[0] < 0) {
      p.push_back(
          "initial.heading: magnetometer needs the magnetometer columns of imu.format (mag: {columns: [i, j, k], "
          "unit: ut | gauss | nt | mgauss})");
    }
  }
  for (const auto& e : engine_options(c).problems()) p.push_back(e);
  return p;
}

Expected<RunInputs> load_run_inputs(const RunConfig& c) { return load_run_inputs(c, nullptr); }

Expected<RunInputs> load_run_inputs(const RunConfig& c, const ImuLog* given_imu) {
  if (const auto problems = run_config_problems(c); !problems.empty()) {
    std::string all;
    for (const auto& m : problems) all += (all.empty() ? "" : "; ") + m;
    return make_error(c.source_file + ": " + all);
  }
  if (auto missing = missing_input_files(c); !missing.empty()) {
    if (given_imu) {  // the log is given: imu.file is not read
      missing.erase(std::remove_if(missing.begin(), missing.end(),
                                   [](const std::string& m) { return m.rfind("imu.file", 0) == 0; }),
                    missing.end());
    }
    std::string all;
    for (const auto& m : missing) all += (all.empty() ? "" : "; ") + m;
    if (!all.empty()) return make_error(c.source_file + ": " + all);
  }
  RunInputs d;
  if (given_imu) {
    d.imu = *given_imu;
  } else {
    auto imu = read_imu_csv(c.imu.file, c.imu.format);
    if (!imu) return imu.error();
    for (const auto& w : imu->report.warnings) spdlog::warn("{}: {}", c.imu.file, w);
    d.imu = std::move(*imu);
  }
  d.config = c;
  d.self_calibration = resolve_self_calibration(d.config, d.imu);
  if (d.self_calibration) {
    for (const auto& w : d.self_calibration->calibration.warnings) spdlog::warn("{}: calibration: {}", c.imu.file, w);
  }
  d.options = engine_options(d.config);
  if (d.options.mode != fusion::Mode::kTightlyCoupled) return d;
  gnss::SystemSelection sel{false, false, false, false, false};
  for (const auto& s : c.gnss.systems) {
    sel.gps |= s == "G";
    sel.glonass |= s == "R";
    sel.galileo |= s == "E";
    sel.beidou |= s == "C";
    sel.qzss |= s == "J";
  }
  auto r = gnss::read_rinex_obs(c.gnss.rover_obs, sel);
  if (!r) return r.error();
  d.rover = std::move(*r);
  auto warn_truncated = [](const std::string& path, const gnss::ObsReadStats& st) {
    if (!st.truncated) return;
    spdlog::warn("{}: truncated: the last epoch record is incomplete (file cut off?){}", path,
                 st.last_epoch_dropped ? "; that epoch was dropped" : "");
  };
  warn_truncated(c.gnss.rover_obs, d.rover->stats);
  auto n = gnss::read_rinex_nav(c.gnss.nav);
  if (!n) return n.error();
  d.nav = std::move(*n);
  if (!c.gnss.base_obs.empty()) {
    auto b = gnss::read_rinex_obs(c.gnss.base_obs, sel);
    if (!b) return b.error();
    d.base = std::move(*b);
    warn_truncated(c.gnss.base_obs, d.base->stats);
    if (c.gnss.base_position_ecef_m) {
      d.options.base_position_e = c.gnss.base_position_ecef_m;
    } else if (d.base->has_approx_position) {
      spdlog::warn("{}: base position taken from the RINEX header APPROX POSITION (approximate; set base_position_ecef_m)",
                   c.gnss.base_obs);
      d.options.base_position_e = d.base->approx_position_e;
    } else {
      return make_error(c.gnss.base_obs + ": no base position (set base_position_ecef_m)");
    }
  }
  // The tight coupling uses the carrier with gnss.carrier: on only; auto keeps it to pednav gnss until the tc phase
  // rows beat the code-only filter on the shared logs (docs/carrier.md §8, docs/results.md "Carrier phase").
  if (c.gnss.carrier == "on") {
    const std::string why_not = carrier_unavailable(c.gnss, *d.rover, d.base ? &*d.base : nullptr);
    if (!why_not.empty()) return make_error(c.source_file + ": gnss.carrier: on, but " + why_not);
    d.options.carrier = true;
    d.options.antenna_state = true;  // the phase measures an antenna that moves smoothly (docs/carrier.md §10)
  }
  return d;
}

SolutionRow antenna_row(const fusion::EpochOutput& e) {
  SolutionRow r = solution_row(e);
  r.p_e = e.ant_p_e;
  const Geodetic llh = geodetic_from_ecef(e.ant_p_e);
  r.v_n = R_e_n(llh.lat, llh.lon).transpose() * e.ant_v_e;
  r.rpy_deg.reset();
  r.sd_yaw_deg.reset();
  r.zupt.reset();
  r.cov_p_n = e.cov_ant_p_n;
  return r;
}

Expected<RunConfig> tc_config(const RunConfig& c, const std::string& command) {
  if (c.mode == "tc") return c;
  std::string missing;
  for (const auto& [key, absent] : {std::pair<const char*, bool>{"imu.file", c.imu.file.empty()},
                                    {"rover_obs", c.gnss.rover_obs.empty()}, {"nav", c.gnss.nav.empty()}}) {
    if (absent) missing += std::string(missing.empty() ? "" : ", ") + key;
  }
  if (!missing.empty()) {
    return make_error(fmt::format("{}: mode {}: {} runs the tightly coupled filter, which needs {} (missing here){}",
                                  c.source_file, c.mode, command, missing,
                                  c.imu.file.empty() ? "; `pednav gnss` gives the GNSS-only solution" : ""));
  }
  spdlog::info("{}: mode {}: {} runs the tightly coupled filter (mode tc) on its IMU log and GNSS files",
               c.source_file, c.mode, command);
  RunConfig t = c;
  t.mode = "tc";
  return t;
}

Expected<RunConfig> run_config_for_mode(const RunConfig& c) {
  if (c.mode == "gnss") return tc_config(c, "pednav run");
  return c;
}

Expected<RunOutputs> compute_run(const RunConfig& c, const RunInputs& data, std::function<bool(GpsTime)> cancel,
                                 const std::string& out_dir) {
  const auto wall0 = std::chrono::steady_clock::now();
  if (c.mode == "gnss") return make_error(c.source_file + ": mode gnss: compute_run needs run_config_for_mode first");
  RunOutputs outputs;
  const ImuLog* imu = &data.imu;
  const std::optional<gnss::ObsData>& base = data.base;
  fusion::EngineOptions opt = data.options;
  fusion::EngineInputs in = data.engine_inputs();
  in.cancel = std::move(cancel);
  opt.record_gnss_rows = opt.mode == fusion::Mode::kTightlyCoupled;  // residuals.csv
  auto res = fusion::run_forward(in, opt);
  if (!res) return make_error(c.source_file + ": " + res.error().message);
  fusion::EngineSummary& sum = res->summary;
  spdlog::info("initialization: {}", sum.initialization);

  std::vector<SolutionRow>& rows = outputs.rows;
  rows.reserve(res->epochs.size());
  for (const auto& e : res->epochs) rows.push_back(solution_row(e));
  std::vector<SolutionRow>& smoothed_rows = outputs.smoothed_rows;
  smoothed_rows.reserve(res->smoothed.size());
  for (const auto& e : res->smoothed) smoothed_rows.push_back(solution_row(e));
  for (const auto& e : res->epochs) {
    if (e.has_antenna) outputs.antenna_rows.push_back(antenna_row(e));
  }
  for (const auto& e : res->smoothed) {
    if (e.has_antenna) outputs.antenna_smoothed_rows.push_back(antenna_row(e));
  }
  if (!sum.smoother_message.empty()) spdlog::warn("{} (only the forward solution is written)", sum.smoother_message);
  for (const auto& note : sum.saturation_notes) spdlog::warn("{}: {}", c.imu.file, note);
  if (sum.saturated_runs > 0) {
    spdlog::info("{}: {} runs of saturated samples ({} samples), {} reconstructed (largest added angle {:.1f} deg)",
                 c.imu.file, sum.saturated_runs, sum.saturated_samples, sum.saturated_runs_reconstructed,
                 sum.saturation_max_added_deg);
  }
  if (!sum.smoothed) smoothed_rows.clear(), outputs.antenna_smoothed_rows.clear();

  nlohmann::ordered_json& j = outputs.summary;
  j["mode"] = c.mode;
  j["initialization"] = sum.initialization;
  j["initial_yaw_deg"] = sum.initial_yaw_deg;
  j["initial_gyro_bias_deg_per_h"] = {sum.initial_gyro_bias_deg_per_h.x(), sum.initial_gyro_bias_deg_per_h.y(),
                                      sum.initial_gyro_bias_deg_per_h.z()};
  j["still_gyro_bias_d2"] = sum.still_gyro_bias_d2;
  if (c.initial.heading_from_magnetometer) {
    // The magnetometer columns are converted to µT by the reader (imu.format mag.unit).
    j["magnetometer"] = {{"declination_deg", c.initial.declination_rad * kRadToDeg},
                         {"field_ut", sum.magnetometer_field_norm},
                         {"dip_deg", sum.magnetometer_dip_deg}};
    if (!(sum.magnetometer_field_norm >= 22.0 && sum.magnetometer_field_norm <= 67.0)) {
      spdlog::warn("{}: magnetometer field {:.1f} µT at the start is outside the Earth's 22-67 µT: a disturbed field "
                   "(steel, electronics) or a wrong mag.unit; the initial heading may be off",
                   c.imu.file, sum.magnetometer_field_norm);
    }
  }
  j["heading_fit_rms_m"] = sum.heading_fit_rms_m;
  if (sum.heading_init_end) {
    j["heading_init_distance_m"] = sum.heading_init_distance_m;
    j["heading_init_end_gps_tow_s"] = sum.heading_init_end->tow_s();
  }
  if (data.self_calibration) j["self_calibration"] = self_calibration_json(*data.self_calibration);
  j["output_epochs"] = res->epochs.size();
  j["imu"] = {{"file", c.imu.file},
              {"rows", imu->report.rows},
              {"samples", imu->report.samples},
              {"duplicates_dropped", imu->report.duplicates_dropped},
              {"bad_rows", imu->report.bad_rows},
              {"gaps", imu->report.gaps},
              {"longest_gap_s", imu->report.longest_gap_s},
              {"samples_processed", sum.imu_samples},
              {"rate_hz", imu->report.rate_hz},
              {"saturation", {{"repair", opt.repair_saturation},
                              {"samples", sum.saturated_samples},
                              {"runs", sum.saturated_runs},
                              {"runs_reconstructed", sum.saturated_runs_reconstructed},
                              {"max_added_angle_deg", sum.saturation_max_added_deg},
                              {"notes", sum.saturation_notes}}}};
  j["mechanization_steps"] = sum.mechanization_steps;
  j["imu_estimate"] = imu_estimate_json(sum.imu_estimate);
  if (c.step_velocity.enabled) j["step_velocity"] = {{"updates", sum.step_velocity_updates}};
  j["zupt"] = zupt_json(c, sum);
  if (opt.mode == fusion::Mode::kTightlyCoupled) {
    j["gnss"] = {{"epochs_read", sum.gnss_epochs},
                 {"epochs_used", sum.gnss_epochs_used},
                 {"epochs_skipped_no_base", sum.gnss_epochs_skipped_no_base},
                 {"epochs_undifferenced_no_base", sum.gnss_epochs_undifferenced_no_base},
                 {"epochs_outside_imu_span", sum.gnss_epochs_before_start},
                 {"epochs_masked", sum.gnss_epochs_masked},
                 {"clock_resets", sum.clock_resets},
                 {"differential", base.has_value()},
                 {"code", sum.code_used_rejected},
                 {"doppler", sum.doppler_used_rejected}};
  }
  j["smoother"] = {{"enabled", c.smoother_enabled},
                   {"ran", sum.smoothed},
                   {"stored_records", sum.smoother_records},
                   {"stored_bytes", sum.smoother_bytes}};
  if (!sum.smoother_message.empty()) j["smoother"]["message"] = sum.smoother_message;
  j["covariance_healthy"] = sum.covariance_healthy;
  j["health"] = {{"healthy", sum.covariance_healthy},
                 {"reinitializations", sum.reinitializations},
                 {"events", sum.health_events}};
  for (const auto& e : sum.health_events) spdlog::warn("{}", e);
  // Does the log fit the model? (docs/fusion.md §15): each warning with its figure and what to try.
  std::vector<RunWarning> warnings = imu_log_warnings(imu->samples);
  for (auto& w : run_warnings(*res, opt.spec)) warnings.push_back(std::move(w));
  j["warnings"] = run_warnings_json(warnings);
  for (const auto& w : warnings) spdlog::warn("{}: {}; {}", c.imu.file, w.message, w.hint);
  j["accounting"] = accounting_json(*imu, data, sum, opt.mode == fusion::Mode::kTightlyCoupled);
  if (opt.carrier) j["carrier"] = carrier_json(sum, res->epochs);
  j["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  if (!c.reference.file.empty()) {
    auto ref = read_configured_reference(c);
    if (!ref) return ref.error();
    // Forward solution -> evaluation.json (unchanged); smoothed -> evaluation_smoothed.json. The file names in the
    // JSON are those run_run_command writes (relative to the output folder when computed in memory).
    auto evaluate = [&](const std::vector<SolutionRow>& rs, const std::string& csv, const std::string& key,
                        const std::string& what, std::string& json_text) -> Expected<void> {
      auto ev = evaluate_rows_text(rs, *ref, c.reference.file, (std::filesystem::path(out_dir) / csv).string(), what);
      if (!ev) return ev.error();
      j[key] = ev->figures;
      json_text = std::move(ev->json_text);
      return {};
    };
    if (auto ok = evaluate(rows, "solution.csv", "evaluation", "forward", outputs.evaluation_json); !ok) {
      return ok.error();
    }
    if (sum.smoothed) {
      if (auto ok = evaluate(smoothed_rows, "smoothed.csv", "evaluation_smoothed", "smoothed",
                             outputs.evaluation_smoothed_json);
          !ok) {
        return ok.error();
      }
    }
  }
  outputs.config = data.config;
  outputs.tightly_coupled = opt.mode == fusion::Mode::kTightlyCoupled;
  outputs.result = std::move(*res);
  return outputs;
}

Expected<fusion::EngineSummary> run_run_command(const RunConfig& given, const std::string& out_dir) {
  const auto wall0 = std::chrono::steady_clock::now();
  auto as_run = run_config_for_mode(given);
  if (!as_run) return as_run.error();
  const RunConfig& c = *as_run;
  auto loaded = load_run_inputs(c);
  if (!loaded) return loaded.error();
  auto computed = compute_run(c, *loaded, {}, out_dir);
  if (!computed) return computed.error();
  if (auto ok = write_run_outputs(c, *computed, out_dir, wall0); !ok) return ok.error();
  return computed->result.summary;
}

Expected<void> write_run_outputs(const RunConfig& c, RunOutputs& o, const std::string& out_dir,
                                 std::optional<std::chrono::steady_clock::time_point> wall0) {
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return make_error(out_dir + ": cannot create output folder: " + ec.message());
  const std::filesystem::path out(out_dir);
  const fusion::EngineSummary& sum = o.result.summary;
  if (auto ok = write_solution_csv((out / "solution.csv").string(), o.rows); !ok) return ok.error();
  if (auto ok = write_solution_pos((out / "solution.pos").string(), o.rows,
                                   {"pednav run (" + c.mode + ", forward filter, IMU position)", c.source_file});
      !ok) {
    return ok.error();
  }
  if (auto ok = write_file_atomic((out / "config.resolved.yaml").string(), to_yaml(o.config)); !ok) return ok.error();
  // Map formats (output.formats: geojson, kml): the forward solution here, the smoothed one below.
  auto write_maps = [&](const std::vector<SolutionRow>& r, const std::string& stem, const std::string& what) -> Expected<void> {
    const auto& f = c.output.formats;
    const std::string title = "pednav run " + c.mode + " (" + what + "): " + c.source_file;
    if (std::find(f.begin(), f.end(), "geojson") != f.end()) {
      if (auto ok = write_solution_geojson((out / (stem + ".geojson")).string(), r, title); !ok) return ok.error();
    }
    if (std::find(f.begin(), f.end(), "kml") != f.end()) {
      if (auto ok = write_solution_kml((out / (stem + ".kml")).string(), r, title); !ok) return ok.error();
    }
    return {};
  };
  if (auto ok = write_maps(o.rows, "solution", "forward"); !ok) return ok.error();
  if (o.tightly_coupled) {
    if (auto ok = write_residuals_csv((out / "residuals.csv").string(), o.result.gnss_rows); !ok) return ok.error();
  }
  if (sum.smoothed) {
    if (auto ok = write_solution_csv((out / "smoothed.csv").string(), o.smoothed_rows); !ok) return ok.error();
    if (auto ok = write_maps(o.smoothed_rows, "smoothed", "RTS smoothed"); !ok) return ok.error();
    if (auto ok = write_solution_pos((out / "solution_smoothed.pos").string(), o.smoothed_rows,
                                     {"pednav run (" + c.mode + ", RTS smoothed, IMU position)", c.source_file});
        !ok) {
      return ok.error();
    }
  }
  // The antenna states' own track (docs/carrier.md §10): what a receiver's RTK solution or a GGA log is compared with.
  if (!o.antenna_rows.empty()) {
    if (auto ok = write_solution_csv((out / "antenna.csv").string(), o.antenna_rows); !ok) return ok.error();
    if (auto ok = write_solution_pos((out / "antenna.pos").string(), o.antenna_rows,
                                     {"pednav run (" + c.mode + ", forward filter, antenna position)", c.source_file});
        !ok) {
      return ok.error();
    }
  }
  if (!o.antenna_smoothed_rows.empty()) {
    if (auto ok = write_solution_csv((out / "antenna_smoothed.csv").string(), o.antenna_smoothed_rows); !ok) {
      return ok.error();
    }
  }
  if (!o.evaluation_json.empty()) {
    if (auto ok = write_file_atomic((out / "evaluation.json").string(), o.evaluation_json); !ok) return ok.error();
  }
  if (!o.evaluation_smoothed_json.empty()) {
    if (auto ok = write_file_atomic((out / "evaluation_smoothed.json").string(), o.evaluation_smoothed_json); !ok) {
      return ok.error();
    }
  }
  if (wall0) o.summary["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - *wall0).count();
  return write_file_atomic((out / "summary.json").string(), o.summary.dump(2) + "\n");
}

}  // namespace pednav::pipeline
