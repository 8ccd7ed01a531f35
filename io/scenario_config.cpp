// SPDX-License-Identifier: BSD-2-Clause
// Scenario YAML reader (docs/configuration.md "Scenario files"). Unit-suffixed keys are converted to SI here.
#include "io/scenario_config.hpp"

#include "core/rotation.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "core/geodesy.hpp"
#include "io/config.hpp"
#include "io/trajectory_io.hpp"
#include "io/yaml_schema.hpp"

namespace pednav::io {
namespace {

constexpr double kG0 = 9.80665;

void read_clock(YamlMap& m, sim::ClockOptions& c) {
  double bias_ms = c.bias_s * 1e3, drift_ppm = c.drift * 1e6, rw_ppb = c.drift_rw * 1e9;
  m.number("bias_ms", bias_ms, false, -1.0, 1.0);
  m.number("drift_ppm", drift_ppm, false, -100.0, 100.0);
  m.number("drift_rw_ppb_per_sqrt_s", rw_ppb, false, 0.0, 1000.0);
  c = {bias_ms * 1e-3, drift_ppm * 1e-6, rw_ppb * 1e-9};
}

void read_gnss(YamlMap& g, sim::GnssOptions& o) {
  g.boolean("enabled", o.enabled);
  g.number("rate_hz", o.rate_hz, false, 0.1, 20.0);
  g.integer("satellites", o.satellites, false, 24, 32);
  double mask_deg = o.elevation_mask_rad * kRadToDeg;
  g.number("elevation_mask_deg", mask_deg, false, 0.0, 60.0);
  o.elevation_mask_rad = mask_deg * kDegToRad;
  g.vector3("base_offset_enu_m", o.base_offset_enu_m);
  g.number("base_antenna_height_m", o.base_antenna_height_m, false, 0.0, 100.0);
  g.number("antenna_height_m", o.antenna_height_m, false, 0.0, 3.0);
  g.number("antenna_bob_m", o.antenna_bob_m, false, 0.0, 0.2);
  g.number("cn0_zenith_dbhz", o.cn0_zenith_dbhz, false, 10.0, 60.0);
  g.number("cn0_horizon_dbhz", o.cn0_horizon_dbhz, false, 0.0, 60.0);
  g.number("cn0_satellite_sd_db", o.cn0_satellite_sd_db, false, 0.0, 10.0);
  g.number("cn0_noise_db", o.cn0_noise_db, false, 0.0, 10.0);
  g.number("tracking_threshold_dbhz", o.tracking_threshold_dbhz, false, 0.0, 60.0);
  g.number("acquisition_threshold_dbhz", o.acquisition_threshold_dbhz, false, 0.0, 60.0);
  g.number("dll_bandwidth_hz", o.dll_bandwidth_hz, false, 0.01, 10.0);
  g.number("correlator_spacing_chips", o.correlator_spacing_chips, false, 0.05, 1.5);
  g.number("integration_time_s", o.integration_time_s, false, 0.001, 1.0);
  g.number("multipath_sigma_m", o.multipath_sigma_m, false, 0.0, 100.0);
  g.number("multipath_cn0_ref_dbhz", o.multipath_cn0_ref_dbhz, false, 0.0, 60.0);
  g.number("multipath_tau_s", o.multipath_tau_s, false, 0.01, 1e5);
  g.number("doppler_sigma_mps", o.doppler_sigma_mps, false, 0.0, 10.0);
  g.number("atmosphere_sd_ppm", o.atmosphere_sd_ppm, false, 0.0, 1000.0);
  g.number("atmosphere_tau_s", o.atmosphere_tau_s, false, 0.01, 1e6);
  {
    YamlMap c = g.map("rover_clock");
    read_clock(c, o.rover_clock);
  }
  {
    YamlMap c = g.map("base_clock");
    read_clock(c, o.base_clock);
  }
  g.number("blunder_rate", o.blunder_rate, false, 0.0, 0.5);
  g.number("blunder_min_m", o.blunder_min_m, false, 0.0, 1e4);
  g.number("blunder_max_m", o.blunder_max_m, false, 0.0, 1e4);
  g.number("blunder_min_s", o.blunder_min_s, false, 0.0, 3600.0);
  g.number("blunder_max_s", o.blunder_max_s, false, 0.0, 3600.0);
  // L1 carrier phase (docs/sim.md §8).
  g.boolean("carrier_phase", o.carrier_phase);
  g.number("atmosphere_sd_iono_fraction", o.atmosphere_sd_iono_fraction, false, 0.0, 1.0);
  g.number("carrier_tracking_threshold_dbhz", o.carrier_tracking_threshold_dbhz, false, 0.0, 60.0);
  g.number("carrier_acquisition_threshold_dbhz", o.carrier_acquisition_threshold_dbhz, false, 0.0, 60.0);
  g.number("pll_bandwidth_hz", o.pll_bandwidth_hz, false, 0.0, 50.0);
  g.number("pll_integration_time_s", o.pll_integration_time_s, false, 0.001, 0.1);
  g.number("carrier_multipath_sigma_m", o.carrier_multipath_sigma_m, false, 0.0, 0.1);
  g.number("carrier_multipath_tau_s", o.carrier_multipath_tau_s, false, 0.01, 1e5);
  g.integer("carrier_ambiguity_max_cycles", o.carrier_ambiguity_max_cycles, false, 0, 10000000);
  g.number("carrier_slip_rate_per_s", o.carrier_slip_rate_per_s, false, 0.0, 10.0);
  g.number("carrier_slip_decade_db", o.carrier_slip_decade_db, false, 0.1, 60.0);
  g.integer("carrier_slip_max_cycles", o.carrier_slip_max_cycles, false, 1, 1000000);
  g.number("carrier_slip_flagged_fraction", o.carrier_slip_flagged_fraction, false, 0.0, 1.0);
  g.number("carrier_half_cycle_probability", o.carrier_half_cycle_probability, false, 0.0, 1.0);
  g.number("carrier_half_cycle_s", o.carrier_half_cycle_s, false, 0.001, 3600.0);
}

// parse_scenario, also handing out the keys it marked as known (scenario_config_keys).
Expected<ScenarioFile> parse_scenario_keys(const std::string& yaml_text, const std::string& source_name,
                                           const std::string& base_dir, std::set<std::string>* keys_read) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    return make_error(source_name + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  if (!root || root.IsNull()) return make_error(source_name + ": scenario is empty");
  auto problems = std::make_shared<YamlProblems>();
  problems->file = source_name;
  ScenarioFile out;
  out.source_file = source_name;
  sim::Scenario& sc = out.scenario;
  std::string track_file, track_format = "auto";
  std::vector<int> track_qualities;
  std::string track_date;
  double track_start_offset_s = 0.0;
  std::vector<std::pair<size_t, Geodetic>> geodetic_wp;  // (waypoint index, position): ENU once the origin is known
  bool origin_given = false;
  {
    YamlMap top(root, "", problems, base_dir);
    top.text("name", sc.name);
    int seed = 1;
    top.integer("seed", seed, true, 0, 2147483647);
    sc.seed = static_cast<uint64_t>(seed);
    if (top.has("start")) {
      YamlMap s = top.map("start");
      int week = 0;
      double tow = 0.0;
      s.integer("gps_week", week, true, 0, 10000);
      s.number("gps_tow_s", tow, true, 0.0, 604799.0);
      if (tow != std::floor(tow)) s.problem("gps_tow_s", "must be a whole second");
      sc.start = GpsTime::from_week_tow(week, std::floor(tow));
    } else if (!top.has("track")) {
      top.problem("start", "required key is missing (route mode)");
    }
    if (top.has("origin")) {
      YamlMap o = top.map("origin");
      double lat = 0, lon = 0, h = 0;
      o.number("lat_deg", lat, true, -89.0, 89.0);
      o.number("lon_deg", lon, true, -180.0, 360.0);
      o.number("h_m", h, false, -500.0, 9000.0);
      sc.origin = {lat * kDegToRad, lon * kDegToRad, h};
      origin_given = true;
    }
    {
      YamlMap r = top.map("route", !top.has("track"));
      r.number("static_start_s", sc.static_start_s, false, 0.0, 86400.0);
      r.number("static_end_s", sc.static_end_s, false, 0.0, 86400.0);
      if (r.has("waypoints") && r.has("shape")) r.problem("shape", "give either waypoints or shape, not both");
      if (r.has("waypoints")) {
        const YAML::Node w = r.raw("waypoints");
        if (!w.IsSequence()) {
          r.problem("waypoints", "expected a list of waypoints");
        } else {
          for (size_t i = 0; i < w.size(); ++i) {
            YamlMap m(w[i], r.yaml_path() + ".waypoints[" + std::to_string(i) + "]", problems, base_dir);
            sim::Waypoint wp;
            m.number("pause_s", wp.pause_s, false, 0.0, 86400.0);
            if (m.has("lat_deg") || m.has("lon_deg")) {
              double lat = 0, lon = 0, h = 0;
              m.number("lat_deg", lat, true, -89.0, 89.0);
              m.number("lon_deg", lon, true, -180.0, 360.0);
              m.number("h_m", h, false, -500.0, 9000.0);
              geodetic_wp.push_back({sc.waypoints.size(), Geodetic{lat * kDegToRad, lon * kDegToRad, h}});
              sc.waypoints.push_back(wp);  // position filled in below
            } else {
              m.number("e_m", wp.p_enu_m.x(), true, -1e5, 1e5);
              m.number("n_m", wp.p_enu_m.y(), true, -1e5, 1e5);
              m.number("u_m", wp.p_enu_m.z(), false, -1e4, 1e4);
              sc.waypoints.push_back(wp);
            }
          }
        }
      } else if (r.has("shape")) {
        YamlMap s = r.map("shape");
        std::string type;
        s.choice("type", type, {"circle", "rectangle"}, true);
        if (type == "circle") {
          double radius = 50.0, length = 2.0 * kPi * 50.0, spacing = 0.5;
          s.number("radius_m", radius, true, 1.0, 1e4);
          s.number("length_m", length, true, 1.0, 1e5);
          s.number("spacing_m", spacing, false, 0.05, 10.0);
          // Counter-clockwise seen from above, starting east of the centre heading north.
          const int n = std::max(2, static_cast<int>(std::ceil(length / spacing)));
          for (int i = 0; i <= n; ++i) {
            const double a = length / radius * i / n;
            sim::Waypoint wp;
            wp.p_enu_m = Eigen::Vector3d(radius * std::cos(a) - radius, radius * std::sin(a), 0.0);
            sc.waypoints.push_back(wp);
          }
        } else if (type == "rectangle") {
          double east = 0, north = 0;
          int laps = 1;
          s.number("east_m", east, true, 0.1, 1e5);
          s.number("north_m", north, true, 0.1, 1e5);
          s.integer("laps", laps, false, 1, 1000);
          sc.waypoints.push_back({});
          for (int l = 0; l < laps; ++l) {
            for (const Eigen::Vector3d& c : {Eigen::Vector3d(east, 0, 0), Eigen::Vector3d(east, north, 0),
                                             Eigen::Vector3d(0, north, 0), Eigen::Vector3d(0, 0, 0)}) {
              sim::Waypoint wp;
              wp.p_enu_m = c;
              sc.waypoints.push_back(wp);
            }
          }
        }
      } else if (!top.has("track")) {
        r.problem("waypoints", "required key is missing (give waypoints or shape)");
      }
    }
    if (top.has("track")) {
      YamlMap t = top.map("track");
      t.path("file", track_file, true);
      t.choice("format", track_format, {"auto", "csv", "pos", "nmea"});
      t.integers("nmea_qualities", track_qualities, kMinGgaQuality, kMaxGgaQuality);
      t.text("nmea_date", track_date);
      t.number("start_offset_s", track_start_offset_s, false, 0.0, 86400.0);
      RealGnssFiles real;
      YamlMap g = t.map("gnss", true);
      g.path("rover_obs", real.rover_obs, true);
      g.path("base_obs", real.base_obs);
      g.paths("nav", real.nav, true);
      if (g.has("base_position_ecef_m")) {
        Eigen::Vector3d b;
        g.vector3("base_position_ecef_m", b);
        real.base_position_ecef_m = b;
      }
      real.reference_file = track_file;
      out.real_gnss = real;
    }
    {
      YamlMap g = top.map("gait");
      sim::GaitOptions& ga = sc.gait;
      g.number("speed_mps", ga.speed_mps, false, 0.1, 5.0);
      g.number("cycle_s", ga.cycle_s, false, 0.5, 3.0);
      g.number("stance_fraction", ga.stance_fraction, false, 0.1, 0.8);
      g.number("cycle_sd_fraction", ga.cycle_sd_fraction, false, 0.0, 0.2);
      g.number("stride_sd_fraction", ga.stride_sd_fraction, false, 0.0, 0.3);
      g.number("clearance_m", ga.clearance_m, false, 0.0, 0.5);
      g.number("pitch_rate_peak_radps", ga.pitch_rate_peak_radps, false, 0.0, 15.0);
      g.number("foot_offset_m", ga.foot_offset_m, false, -0.5, 0.5);
      g.number("imu_height_m", ga.imu_height_m, false, 0.0, 0.3);
      double max_turn_deg = ga.max_turn_per_stride_rad * kRadToDeg;
      g.number("max_turn_per_stride_deg", max_turn_deg, false, 10.0, 180.0);
      ga.max_turn_per_stride_rad = max_turn_deg * kDegToRad;
    }
    {
      YamlMap m = top.map("imu");
      sim::ImuOptions& o = sc.imu;
      m.number("rate_hz", o.rate_hz, false, 20.0, 2000.0);
      // spec: a preset name, or a map {preset: NAME, <ImuSpec keys>...} overriding the preset's values (the vocabulary
      // of a run configuration's imu.spec), e.g. a wider gyro range.
      out.imu_spec_preset = "crista";
      read_imu_spec_entry(m, "spec", o.spec, out.imu_spec_preset);
      m.boolean("errors", o.errors);
      m.choice("carry", o.carry, {"foot", "hand"});
      double mis_mrad = o.misalignment_sigma_rad * 1e3;
      m.number("misalignment_mrad", mis_mrad, false, 0.0, 100.0);
      o.misalignment_sigma_rad = mis_mrad * 1e-3;
      // The truth's g-sensitivity σ: this key, else the spec's (the filter's data-sheet value, docs/error_state.md §5).
      if (o.spec.gyro_g_sensitivity > 0.0) o.gyro_g_sensitivity_sigma = o.spec.gyro_g_sensitivity;
      double gs = o.gyro_g_sensitivity_sigma * kRadToDeg * kG0;
      m.number("gyro_g_sensitivity_deg_per_s_per_g", gs, false, 0.0, 10.0);
      o.gyro_g_sensitivity_sigma = gs * kDegToRad / kG0;
      double gq = o.gyro_quantum_radps * kRadToDeg, aq = o.accel_quantum_mps2 / kG0 * 1e3;
      m.number("gyro_quantum_deg_per_s", gq, false, 0.0, 10.0);
      m.number("accel_quantum_mg", aq, false, 0.0, 1000.0);
      o.gyro_quantum_radps = gq * kDegToRad;
      o.accel_quantum_mps2 = aq * 1e-3 * kG0;
      if (m.has("mounting_rpy_deg")) {  // the sensor's axes on the foot (sim::ImuOptions::R_b_s)
        Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
        m.vector3("mounting_rpy_deg", rpy);
        o.R_b_s = R_n_b_from_euler(rpy.x() * kDegToRad, rpy.y() * kDegToRad, rpy.z() * kDegToRad);
      }
    }
    {
      YamlMap g = top.map("gnss");
      read_gnss(g, sc.gnss);
      if (g.has("attenuation")) {
        const YAML::Node a = g.raw("attenuation");
        if (!a.IsSequence()) {
          g.problem("attenuation", "expected a list of segments");
        } else {
          for (size_t i = 0; i < a.size(); ++i) {
            YamlMap m(a[i], "gnss.attenuation[" + std::to_string(i) + "]", problems, base_dir);
            sim::AttenuationSegment s;
            m.number("from_m", s.from_m, true, 0.0, 1e6);
            m.number("to_m", s.to_m, true, 0.0, 1e6);
            m.choice("type", s.type, {"open", "foliage", "indoor"}, true);
            m.number("min_db", s.min_db, s.type == "foliage", 0.0, 60.0);
            m.number("max_db", s.max_db, s.type == "foliage", 0.0, 60.0);
            m.number("tau_s", s.tau_s, false, 0.01, 1e5);
            sc.gnss.attenuation.push_back(s);
          }
        }
      }
    }
    if (!origin_given && geodetic_wp.empty() && !top.has("track"))
      top.problem("origin", "required key is missing (route waypoints in ENU need a geodetic origin)");
    {
      YamlMap o = top.map("output");
      o.number("truth_rate_hz", sc.truth_rate_hz, false, 0.1, 2000.0);
    }
    top.finish();
  }
  if (keys_read) keys_read->insert(problems->keys_read.begin(), problems->keys_read.end());
  if (!problems->empty()) return make_error(problems->joined());
  // Geodetic waypoints -> ENU at the origin (the first waypoint when no origin is given).
  if (!geodetic_wp.empty()) {
    if (!origin_given) sc.origin = geodetic_wp.front().second;
    const Eigen::Vector3d o_e = ecef_from_geodetic(sc.origin);
    for (const auto& [i, llh] : geodetic_wp) sc.waypoints[i].p_enu_m = enu_from_ecef(ecef_from_geodetic(llh), o_e);
  }
  if (!track_file.empty()) {
    TrajectoryReadOptions ro;
    if (auto f = parse_trajectory_format(track_format)) ro.format = *f;
    ro.nmea_qualities.insert(track_qualities.begin(), track_qualities.end());
    ro.nmea_date = track_date;
    auto tf = read_trajectory(track_file, ro);
    if (!tf) return make_error(source_name + ": track.file: " + tf.error().message);
    if (tf->trajectory.frame != eval::Frame::kEcef)
      return make_error(source_name + ": track.file: the track must be geodetic/ECEF, not a local frame");
    for (const auto& p : tf->trajectory.points) sc.track.push_back({p.t, p.p});
    if (sc.track.size() < 2) return make_error(source_name + ": track.file: fewer than 2 positions");
    const int64_t first_ns = sc.track.front().t.ns();
    int64_t s = (first_ns + kNsPerS - 1) / kNsPerS * kNsPerS;
    sc.start = GpsTime::from_ns(s).plus_s(std::round(track_start_offset_s));
    out.real_gnss->reference_format = tf->format;
  }
  return out;
}

}  // namespace

Expected<ScenarioFile> parse_scenario(const std::string& yaml_text, const std::string& source_name,
                                      const std::string& base_dir) {
  return parse_scenario_keys(yaml_text, source_name, base_dir, nullptr);
}

std::vector<std::string> scenario_config_keys() {
  // The reader's branches: waypoints (ENU and geodetic items), each route shape, the along-a-track mode with a base
  // position, the optional start/origin/mounting/attenuation parts. A new optional branch belongs here, or its keys
  // go unchecked. Each probe fails validation (missing required keys) before any file is read.
  const char* probes[] = {
      "start: {}\norigin: {}\nroute: {waypoints: [{lat_deg: 0}, {}]}\n"
      "track: {gnss: {base_position_ecef_m: [0, 0, 0]}}\n"
      "imu: {spec: {}, mounting_rpy_deg: [0, 0, 0]}\ngnss: {attenuation: [{}]}\n",
      "route: {shape: {type: circle}}\n",
      "route: {shape: {type: rectangle}}\n",
  };
  std::set<std::string> keys;
  for (const char* p : probes) (void)parse_scenario_keys(p, "(probe)", ".", &keys);
  return {keys.begin(), keys.end()};
}

Expected<ScenarioFile> load_scenario(const std::string& path) {
  auto src = read_yaml_source(path, "scenario file");
  if (!src) return src.error();
  return parse_scenario(src->text, path, src->base_dir);
}

}  // namespace pednav::io
