// SPDX-License-Identifier: BSD-2-Clause
#include "io/config.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "io/trajectory_io.hpp"
#include "io/yaml_schema.hpp"

namespace pednav::io {

namespace {

// A path as the resolved configuration writes it: absolute, so that the file reads back from any folder (paths in a
// configuration are relative to the configuration's own folder, and config.resolved.yaml lives in the output folder).
std::string absolute_path(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path a = std::filesystem::absolute(path, ec);
  return ec ? path : a.lexically_normal().string();
}

std::vector<std::string> absolute_paths(const std::vector<std::string>& paths) {
  std::vector<std::string> out;
  for (const auto& p : paths) out.push_back(absolute_path(p));
  return out;
}

// parse_run_config, also handing out the keys it marked as known (run_config_keys).
Expected<RunConfig> parse_run_config_keys(const std::string& yaml_text, const std::string& source_name,
                                          const std::string& base_dir, std::set<std::string>* keys_read) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    return make_error(source_name + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  auto problems = std::make_shared<YamlProblems>();
  problems->file = source_name;
  if (!root || root.IsNull()) return make_error(source_name + ": configuration is empty");
  RunConfig cfg;
  cfg.source_file = source_name;
  {
    YamlMap top(root, "", problems, base_dir);
    top.choice("mode", cfg.mode, {"tc", "ins", "gnss"});
    read_gnss_section(top, cfg.gnss);
    read_imu_section(top, cfg.imu);
    read_filter_section(top, cfg);
    {
      YamlMap ref = top.map("reference");
      ref.path("file", cfg.reference.file, top.has("reference"));
      ref.choice("format", cfg.reference.format, {"csv", "pos", "nmea"});
      ref.integers("nmea_qualities", cfg.reference.nmea_qualities, kMinGgaQuality, kMaxGgaQuality);
    }
    {
      YamlMap out = top.map("output");
      out.number("rate_hz", cfg.output.rate_hz, false, 1e-6, 1000.0);
      out.strings("formats", cfg.output.formats);
      for (const auto& f : cfg.output.formats) {
        if (f != "csv" && f != "pos" && f != "geojson" && f != "kml")
          out.problem("formats", "unknown output format '" + f + "' (expected csv, pos, geojson, kml)");
      }
    }
    // Mode-dependent required inputs.
    if (cfg.mode != "ins") {
      if (cfg.gnss.rover_obs.empty() && !top.has("rover_obs")) top.problem("rover_obs", "required key is missing (mode " + cfg.mode + ")");
      if (cfg.gnss.nav.empty() && !top.has("nav")) top.problem("nav", "required key is missing (mode " + cfg.mode + ")");
    }
    if (cfg.mode != "gnss" && cfg.imu.file.empty() && !top.has("imu")) {
      top.problem("imu", "required key is missing (mode " + cfg.mode + ")");
    }
    top.finish();
  }
  if (keys_read) keys_read->insert(problems->keys_read.begin(), problems->keys_read.end());
  if (!problems->empty()) return make_error(problems->joined());
  return cfg;
}

}  // namespace

Expected<RunConfig> parse_run_config(const std::string& yaml_text, const std::string& source_name,
                                     const std::string& base_dir) {
  return parse_run_config_keys(yaml_text, source_name, base_dir, nullptr);
}

std::vector<std::string> run_config_keys() {
  // Each branch of the reader that only reads keys when a section is there (imu.format as a mapping with its
  // optional stance/mag/mounting parts, imu.spec as a mapping, an initial position, a fixed SHOE threshold, explicit
  // scale-factor states). A new optional branch belongs here, or its keys go unchecked.
  const char* probe = R"(
base_position_ecef_m: [0, 0, 0]
imu:
  format: {stance: {}, mag: {}, mounting_rpy_deg: [0, 0, 0]}
  spec: {}
initial: {yaw_deg: 0, position_ecef_m: [0, 0, 0], lat_deg: 0}
zupt: {shoe_threshold: 1}
scale_factors: {states: auto}
reference: {}
)";
  std::set<std::string> keys;
  (void)parse_run_config_keys(probe, "(probe)", ".", &keys);
  return {keys.begin(), keys.end()};
}

Expected<RunConfig> load_run_config(const std::string& path) {
  auto src = read_yaml_source(path, "configuration file");
  if (!src) return src.error();
  return parse_run_config(src->text, path, src->base_dir);
}

// docs/consistency.md §3.3-3.4: in mode tc the GNSS observes the scale factors and the turn-on biases, so the filter
// gets the scale-factor states (gyro and accelerometer) and the random-walk bias model. In mode ins it gets the
// scale-factor states only for an uncalibrated sensor, data-sheet gyro scale-factor σ ≥ 1 % (§3.16: 1 % of every
// turn is then its largest heading error; on calibrated sensors, 0.05-0.5 %, the states cost accuracy).
ImuErrorModelChoice imu_error_model_choice(const RunConfig& c) {
  constexpr double kUncalibratedGyroScaleSigma = 0.01;
  const bool tc = c.mode == "tc";
  ImuErrorModelChoice m;
  m.scale_states = c.scale_factors.states.value_or(tc || c.imu.spec.gyro_scale_sigma >= kUncalibratedGyroScaleSigma);
  m.gyro_scale_states = m.scale_states && c.scale_factors.gyro;
  m.bias_random_walk = c.bias.model == "auto" ? tc : c.bias.model == "random_walk";
  return m;
}

std::string to_yaml(const RunConfig& c) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "mode" << YAML::Value << c.mode;
  if (!c.gnss.rover_obs.empty()) e << YAML::Key << "rover_obs" << YAML::Value << absolute_path(c.gnss.rover_obs);
  if (!c.gnss.base_obs.empty()) e << YAML::Key << "base_obs" << YAML::Value << absolute_path(c.gnss.base_obs);
  if (!c.gnss.nav.empty()) e << YAML::Key << "nav" << YAML::Value << absolute_paths(c.gnss.nav);
  if (c.gnss.base_position_ecef_m) {
    const auto& b = *c.gnss.base_position_ecef_m;
    e << YAML::Key << "base_position_ecef_m" << YAML::Value << YAML::Flow << yaml_numbers({b.x(), b.y(), b.z()});
  }
  e << YAML::Key << "gnss" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "systems" << YAML::Value << YAML::Flow << c.gnss.systems;
  e << YAML::Key << "elevation_mask_deg" << YAML::Value
    << yaml_number(c.gnss.elevation_mask_rad * 180.0 / 3.14159265358979323846);
  e << YAML::Key << "epoch_match_tolerance_s" << YAML::Value << yaml_number(c.gnss.epoch_match_tolerance_s);
  e << YAML::Key << "max_base_age_s" << YAML::Value << yaml_number(c.gnss.max_base_age_s);
  e << YAML::Key << "min_cn0_dbhz" << YAML::Value << yaml_number(c.gnss.min_cn0_dbhz);
  e << YAML::Key << "base_propagation" << YAML::Value << c.gnss.base_propagation;
  e << YAML::Key << "code_sigma_zenith_m" << YAML::Value << yaml_number(c.gnss.code_sigma_zenith_m);
  e << YAML::Key << "doppler_sigma_zenith_mps" << YAML::Value << yaml_number(c.gnss.doppler_sigma_zenith_mps);
  e << YAML::Key << "cn0_ref_dbhz" << YAML::Value << yaml_number(c.gnss.cn0_ref_dbhz);
  e << YAML::Key << "glonass_code_factor" << YAML::Value << yaml_number(c.gnss.glonass_code_factor);
  e << YAML::Key << "elevation_weight" << YAML::Value << yaml_number(c.gnss.elevation_weight);
  e << YAML::Key << "code_squaring_loss" << YAML::Value << yaml_number(c.gnss.code_squaring_loss);
  e << YAML::Key << "code_smoothing_s" << YAML::Value << yaml_number(c.gnss.code_smoothing_s);
  e << YAML::Key << "carrier" << YAML::Value << c.gnss.carrier;
  e << YAML::Key << "carrier_sigma_zenith_m" << YAML::Value << yaml_number(c.gnss.carrier_sigma_zenith_m);
  e << YAML::Key << "carrier_base_age_sigma_mps" << YAML::Value << yaml_number(c.gnss.carrier_base_age_sigma_mps);
  e << YAML::Key << "rtk_accel_sigma_horizontal_mps2" << YAML::Value << yaml_number(c.gnss.rtk_accel_sigma_horizontal_mps2);
  e << YAML::Key << "rtk_accel_sigma_vertical_mps2" << YAML::Value << yaml_number(c.gnss.rtk_accel_sigma_vertical_mps2);
  {
    const auto& a = c.gnss.ambiguity;
    e << YAML::Key << "ambiguity" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "ratio_threshold" << YAML::Value << yaml_number(a.ratio_threshold);
    e << YAML::Key << "tc_ratio_threshold" << YAML::Value << yaml_number(a.tc_ratio_threshold);
    e << YAML::Key << "min_success_rate" << YAML::Value << yaml_number(a.min_success_rate);
    e << YAML::Key << "elevation_mask_deg" << YAML::Value << yaml_number(a.elevation_mask_deg);
    e << YAML::Key << "partial" << YAML::Value << a.partial;
    e << YAML::Key << "min_ambiguities" << YAML::Value << a.min_ambiguities;
    e << YAML::Key << "min_lock_epochs" << YAML::Value << a.min_lock_epochs;
    e << YAML::Key << "hold" << YAML::Value << a.hold;
    e << YAML::Key << "hold_min_epochs" << YAML::Value << a.hold_min_epochs;
    e << YAML::Key << "hold_sigma_cycles" << YAML::Value << yaml_number(a.hold_sigma_cycles);
    e << YAML::Key << "validation_w" << YAML::Value << yaml_number(a.validation_w);
    e << YAML::Key << "glonass" << YAML::Value << a.glonass;
    e << YAML::Key << "glonass_ifb" << YAML::Value << a.glonass_ifb;
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  if (!c.imu.file.empty()) {
    e << YAML::Key << "imu" << YAML::Value << YAML::BeginMap << YAML::Key << "file" << YAML::Value << absolute_path(c.imu.file);
    if (!c.imu.format_preset.empty()) {
      e << YAML::Key << "format" << YAML::Value << c.imu.format_preset;
    } else if (c.imu.has_format) {
      e << YAML::Key << "format" << YAML::Value;
      emit_imu_format(e, c.imu.format);
    }
    if (c.imu.spec_auto) {
      e << YAML::Key << "spec" << YAML::Value << "auto";
    } else if (!c.imu.spec_preset.empty() || c.imu.spec.name == "inline") {
      e << YAML::Key << "spec" << YAML::Value;
      emit_imu_spec(e, c.imu.spec, c.imu.spec_preset);
    }
    e << YAML::EndMap;
  }
  if (!c.reference.file.empty()) {
    e << YAML::Key << "reference" << YAML::Value << YAML::BeginMap << YAML::Key << "file" << YAML::Value
      << absolute_path(c.reference.file) << YAML::Key << "format" << YAML::Value << c.reference.format;
    if (!c.reference.nmea_qualities.empty()) {
      e << YAML::Key << "nmea_qualities" << YAML::Value << YAML::Flow << c.reference.nmea_qualities;
    }
    e << YAML::EndMap;
  }
  const Eigen::Vector3d& l = c.antenna.lever_arm_ned_m;
  const Eigen::Vector3d& lh = c.antenna.lever_arm_heading_m;
  e << YAML::Key << "antenna" << YAML::Value << YAML::BeginMap << YAML::Key << "lever_arm_ned_m" << YAML::Value
    << YAML::Flow << yaml_numbers({l.x(), l.y(), l.z()}) << YAML::Key << "lever_arm_heading_m" << YAML::Value
    << YAML::Flow << yaml_numbers({lh.x(), lh.y(), lh.z()}) << YAML::Key << "sigma_horizontal_m" << YAML::Value
    << yaml_number(c.antenna.sigma_horizontal_m) << YAML::Key << "sigma_vertical_m" << YAML::Value
    << yaml_number(c.antenna.sigma_vertical_m) << YAML::Key << "velocity_model" << YAML::Value
    << c.antenna.velocity_model << YAML::Key << "velocity_sigma_horizontal_mps" << YAML::Value
    << yaml_number(c.antenna.velocity_sigma_horizontal_mps) << YAML::Key << "velocity_sigma_vertical_mps" << YAML::Value
    << yaml_number(c.antenna.velocity_sigma_vertical_mps) << YAML::Key << "stride_velocity_sigma_horizontal_mps"
    << YAML::Value << yaml_number(c.antenna.stride_velocity_sigma_horizontal_mps) << YAML::Key
    << "stride_velocity_sigma_vertical_mps" << YAML::Value << yaml_number(c.antenna.stride_velocity_sigma_vertical_mps)
    << YAML::Key << "stance_sigma_horizontal_m" << YAML::Value << yaml_number(c.antenna.stance_sigma_horizontal_m)
    << YAML::Key << "stance_sigma_vertical_m" << YAML::Value << yaml_number(c.antenna.stance_sigma_vertical_m)
    << YAML::EndMap;
  {
    const InitialConfig& i = c.initial;
    constexpr double kDeg = 180.0 / 3.14159265358979323846;
    e << YAML::Key << "initial" << YAML::Value << YAML::BeginMap;
    if (i.position_e) {
      e << YAML::Key << "position_ecef_m" << YAML::Value << YAML::Flow
        << yaml_numbers({i.position_e->x(), i.position_e->y(), i.position_e->z()});
    }
    if (i.yaw_rad) e << YAML::Key << "yaw_deg" << YAML::Value << yaml_number(*i.yaw_rad * kDeg);
    if (i.heading_from_magnetometer) {
      e << YAML::Key << "heading" << YAML::Value << "magnetometer" << YAML::Key << "declination_deg" << YAML::Value
        << yaml_number(i.declination_rad * kDeg);
    }
    e << YAML::Key << "heading_init_distance_m" << YAML::Value << yaml_number(i.heading_init_distance_m) << YAML::Key
      << "sigma_position_m" << YAML::Value << yaml_number(i.sigma_position_m) << YAML::Key << "sigma_velocity_mps"
      << YAML::Value << yaml_number(i.sigma_velocity_mps) << YAML::Key << "sigma_tilt_deg" << YAML::Value
      << yaml_number(i.sigma_tilt_rad * kDeg) << YAML::Key << "sigma_yaw_deg" << YAML::Value
      << yaml_number(i.sigma_yaw_rad * kDeg) << YAML::EndMap;
  }
  e << YAML::Key << "mechanization_rate_hz" << YAML::Value << yaml_number(c.mechanization_rate_hz);
  {
    // Every detector and update key, so that a run of config.resolved.yaml repeats the run that wrote it (the auto
    // threshold, its gait-adaptive raise and the ZARU noise resolved from the log included).
    const ZuptConfig& z = c.zupt;
    auto num = [&e](const char* key, double v) { e << YAML::Key << key << YAML::Value << yaml_number(v); };
    auto deg = [&e](const char* key, double rad) { e << YAML::Key << key << YAML::Value << yaml_degrees(rad); };
    e << YAML::Key << "zupt" << YAML::Value << YAML::BeginMap << YAML::Key << "detector" << YAML::Value << z.detector
      << YAML::Key << "form" << YAML::Value << z.form;
    num("mv_window_s", z.mv_window_s);
    num("mv_threshold_mps2", z.mv_threshold_mps2);
    deg("mv_gyro_threshold_deg_per_s", z.mv_gyro_threshold_radps);
    num("min_time_since_step_s", z.min_time_since_step_s);
    num("shoe_window_s", z.shoe_window_s);
    num("shoe_sigma_accel_mps2", z.shoe_sigma_accel_mps2);
    deg("shoe_sigma_gyro_deg_per_s", z.shoe_sigma_gyro_radps);
    if (z.shoe_threshold_auto) {
      e << YAML::Key << "shoe_threshold" << YAML::Value << "auto";
      num("shoe_threshold_motion", z.shoe_threshold_motion);
      num("shoe_threshold_two_class_cap", z.shoe_threshold_two_class_cap);
    } else {
      num("shoe_threshold", z.shoe_threshold);
    }
    num("shoe_adaptive_factor", z.shoe_adaptive_factor);
    num("shoe_adaptive_window_s", z.shoe_adaptive_window_s);
    deg("shoe_adaptive_min_peak_rate_deg_per_s", z.shoe_adaptive_min_peak_radps);
    num("min_stance_s", z.min_stance_s);
    num("are_threshold", z.are_threshold);
    num("mag_threshold", z.mag_threshold);
    e << YAML::Key << "hmm_gyro_axis" << YAML::Value << z.hmm_gyro_axis;
    num("hmm_smooth_window_s", z.hmm_smooth_window_s);
    deg("hmm_grade_width_deg_per_s", z.hmm_grade_width_radps);
    if (!z.hmm_model_file.empty()) e << YAML::Key << "hmm_model" << YAML::Value << absolute_path(z.hmm_model_file);
    e << YAML::Key << "hmm_train_on_log" << YAML::Value << z.hmm_train_on_log << YAML::Key << "hmm_auto_sign"
      << YAML::Value << z.hmm_auto_sign << YAML::Key << "hmm_max_iterations" << YAML::Value << z.hmm_max_iterations
      << YAML::Key << "hmm_decoder" << YAML::Value << z.hmm_decoder;
    num("hmm_rest_s", z.hmm_rest_s);
    num("hmm_min_swing_s", z.hmm_min_swing_s);
    num("hmm_refine_factor", z.hmm_refine_factor);
    num("sigma_mps", z.sigma_mps);
    num("edge_s", z.edge_s);
    e << YAML::Key << "updates" << YAML::Value << z.updates << YAML::Key << "zaru" << YAML::Value << z.zaru;
    deg("zaru_sigma_deg_per_s", z.zaru_sigma_radps);
    num("zaru_gate_probability", z.zaru_gate_probability);
    e << YAML::EndMap;
  }
  e << YAML::Key << "fault_rejection" << YAML::Value << YAML::BeginMap << YAML::Key << "probability" << YAML::Value
    << yaml_number(c.fault_rejection_probability) << YAML::Key << "window_epochs" << YAML::Value
    << c.fault_rejection_window_epochs << YAML::EndMap;
  e << YAML::Key << "smoother" << YAML::Value << YAML::BeginMap << YAML::Key << "enabled" << YAML::Value
    << c.smoother_enabled << YAML::EndMap;
  e << YAML::Key << "multipath" << YAML::Value << YAML::BeginMap << YAML::Key << "states" << YAML::Value
    << c.multipath.states << YAML::Key << "sigma_m" << YAML::Value << yaml_number(c.multipath.sigma_m) << YAML::Key
    << "tau_s" << YAML::Value << yaml_number(c.multipath.tau_s) << YAML::Key << "cn0_ref_dbhz" << YAML::Value
    << yaml_number(c.multipath.cn0_ref_dbhz) << YAML::Key << "slots" << YAML::Value << c.multipath.slots << YAML::Key
    << "reset_gap_s" << YAML::Value << yaml_number(c.multipath.reset_gap_s) << YAML::EndMap;
  const ImuErrorModelChoice m = imu_error_model_choice(c);  // written resolved: what this run's filter used
  e << YAML::Key << "scale_factors" << YAML::Value << YAML::BeginMap << YAML::Key << "states" << YAML::Value
    << m.scale_states << YAML::Key << "gyro" << YAML::Value << c.scale_factors.gyro << YAML::Key
    << "bias_compensation" << YAML::Value << c.scale_factors.bias_compensation
    << YAML::EndMap;
  e << YAML::Key << "bias" << YAML::Value << YAML::BeginMap << YAML::Key << "model" << YAML::Value
    << (m.bias_random_walk ? "random_walk" : "gauss_markov") << YAML::EndMap;
  e << YAML::Key << "saturation" << YAML::Value << YAML::BeginMap << YAML::Key << "repair" << YAML::Value
    << c.saturation.repair << YAML::EndMap;
  {
    const fusion::StepVelocityOptions& sv = c.step_velocity;
    e << YAML::Key << "step_velocity" << YAML::Value << YAML::BeginMap << YAML::Key << "enabled" << YAML::Value
      << sv.enabled << YAML::Key << "leg_length_m" << YAML::Value << yaml_number(sv.leg_length_m) << YAML::Key
      << "sigma_along_mps" << YAML::Value << yaml_number(sv.sigma_along_mps) << YAML::Key << "sigma_cross_mps"
      << YAML::Value << yaml_number(sv.sigma_cross_mps) << YAML::Key << "sigma_vertical_mps" << YAML::Value
      << yaml_number(sv.sigma_vertical_mps) << YAML::Key << "min_step_s" << YAML::Value << yaml_number(sv.min_step_s)
      << YAML::Key << "max_step_s" << YAML::Value << yaml_number(sv.max_step_s) << YAML::Key << "min_rise_m"
      << YAML::Value << yaml_number(sv.min_rise_m) << YAML::EndMap;
  }
  e << YAML::Key << "output" << YAML::Value << YAML::BeginMap << YAML::Key << "rate_hz" << YAML::Value
    << yaml_number(c.output.rate_hz) << YAML::Key << "formats" << YAML::Value << YAML::Flow << c.output.formats
    << YAML::EndMap;
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

std::vector<std::string> missing_input_files(const RunConfig& c) {
  std::vector<std::string> out;
  auto check = [&](const std::string& key, const std::string& path) {
    if (!path.empty() && !std::filesystem::exists(path)) out.push_back(key + ": " + path + " does not exist");
  };
  check("imu.file", c.imu.file);
  if (c.mode != "ins") {
    check("rover_obs", c.gnss.rover_obs);
    check("base_obs", c.gnss.base_obs);
    for (const auto& n : c.gnss.nav) check("nav", n);
  }
  check("reference.file", c.reference.file);
  check("zupt.hmm_model", c.zupt.hmm_model_file);
  return out;
}

}  // namespace pednav::io
