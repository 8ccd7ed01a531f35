// SPDX-License-Identifier: BSD-2-Clause
// Shared scenario texts and helpers of the simulator tests.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "fusion/engine.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "io/scenario_config.hpp"
#include "sim/simulator.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::test {

/// A 10-minute noise-free walk: corridor legs, right-angle and U-turns, stairs (3 m up and down), a pause.
inline const char* kNoiseFreeWalkYaml = R"(
name: noise_free_walk
seed: 11
start: {gps_week: 2300, gps_tow_s: 100000}
origin: {lat_deg: 47.3, lon_deg: 8.5, h_m: 500}
route:
  static_start_s: 10
  static_end_s: 5
  waypoints:
    - {e_m: 0, n_m: 0}
    - {e_m: 60, n_m: 0}
    - {e_m: 60, n_m: 40, pause_s: 8}
    - {e_m: 0, n_m: 40}
    - {e_m: 0, n_m: 0}
    - {e_m: 30, n_m: 0}
    - {e_m: 36, n_m: 0, u_m: 3}
    - {e_m: 60, n_m: 0, u_m: 3}
    - {e_m: 66, n_m: 0, u_m: 0}
    - {e_m: 120, n_m: 0}
    - {e_m: 120, n_m: 80}
    - {e_m: 20, n_m: 80}
    - {e_m: 20, n_m: 10}
    - {e_m: 100, n_m: 10}
    - {e_m: 100, n_m: 60}
    - {e_m: 40, n_m: 60}
    - {e_m: 40, n_m: 20}
    - {e_m: 80, n_m: 20}
    - {e_m: 80, n_m: 70}
    - {e_m: 10, n_m: 70}
    - {e_m: 10, n_m: 5}
    - {e_m: 110, n_m: 5}
    - {e_m: 0, n_m: 5}
gait: {speed_mps: 1.3, cycle_s: 1.1, stance_fraction: 0.3, pitch_rate_peak_radps: 7.0}
imu: {rate_hz: 100, spec: crista, errors: false}
gnss: {enabled: false}
)";

/// Parse a scenario text (fails the test on error).
/// A short walk of the robustness tests: `laps` laps of a 30 m x 20 m rectangle after a 20 s static start, Crista
/// IMU at 100 Hz with errors, 1 Hz rover + base (base 100 m E, 50 m N, 2 m up), truth at 10 Hz.
inline std::string small_rectangle_walk_yaml(const std::string& name, int seed, int gps_tow_s, const char* origin,
                                             int laps) {
  std::ostringstream y;
  y << "\nname: " << name << "\nseed: " << seed << "\nstart: {gps_week: 2300, gps_tow_s: " << gps_tow_s
    << "}\norigin: " << origin
    << "\nroute:\n  static_start_s: 20\n  static_end_s: 5\n  shape: {type: rectangle, east_m: 30, north_m: 20, laps: "
    << laps << "}\ngait: {speed_mps: 1.2, cycle_s: 1.1}\nimu: {rate_hz: 100, spec: crista, errors: true}\n"
    << "gnss: {base_offset_enu_m: [100, 50, 2]}\noutput: {truth_rate_hz: 10}\n";
  return y.str();
}

inline io::ScenarioFile scenario_from_text(const std::string& text) {
  auto sc = io::parse_scenario(text, "test.yaml", ".");
  EXPECT_TRUE(sc.has_value()) << (sc ? "" : sc.error().message);
  return sc ? *sc : io::ScenarioFile{};
}

/// Engine inputs pointing into a simulation (IMU, nav, rover and base epochs); valid while `s` lives.
inline fusion::EngineInputs engine_inputs(const sim::Simulation& s) {
  fusion::EngineInputs in;
  in.imu = &s.imu;
  in.nav = &s.nav;
  in.rover = &s.gnss.rover.epochs;
  in.base = &s.gnss.base.epochs;
  return in;
}

/// `pednav run`'s defaults in mode tc for a simulated scenario (the configuration `pednav simulate` writes, with
/// mode tc): IMU spec of the scenario, base position of the simulation.
inline fusion::EngineOptions tc_default_options(const io::ScenarioFile& file, const sim::Simulation& s) {
  io::RunConfig c;
  c.mode = "tc";
  c.imu.spec = file.scenario.imu.spec;
  fusion::EngineOptions o = pipeline::engine_options(c);
  o.base_position_e = s.gnss.p_base_e;
  return o;
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Rows of a simple numeric CSV with a header (non-numeric cells become NaN).
inline std::vector<std::vector<double>> read_numeric_csv(const std::string& path, std::vector<std::string>* header) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::vector<double>> rows;
  if (std::getline(in, line) && header) {
    std::stringstream hs(line);
    std::string c;
    while (std::getline(hs, c, ',')) header->push_back(c);
  }
  while (std::getline(in, line)) {
    std::vector<double> r;
    std::stringstream ls(line);
    std::string c;
    while (std::getline(ls, c, ',')) {
      char* end = nullptr;
      const double v = std::strtod(c.c_str(), &end);
      r.push_back(end != c.c_str() ? v : std::nan(""));
    }
    rows.push_back(r);
  }
  return rows;
}

}  // namespace pednav::test

namespace pednav::test {

/// A 15-minute open-sky walk with a constant C/N0 (45 dB-Hz on every satellite, no C/N0 noise) so the
/// configured noise levels are known exactly; blunders off unless a test sets them.
inline const char* kOpenSkyGnssYaml = R"(
name: open_sky_gnss
seed: 21
start: {gps_week: 2300, gps_tow_s: 300000}
origin: {lat_deg: -33.9, lon_deg: 151.2, h_m: 40}
route:
  static_start_s: 20
  static_end_s: 10
  shape: {type: rectangle, east_m: 120, north_m: 60, laps: 3}
gait: {speed_mps: 1.2, cycle_s: 1.1}
imu: {rate_hz: 100, spec: crista, errors: true}
gnss:
  base_offset_enu_m: [300, 400, 5]
  cn0_zenith_dbhz: 45
  cn0_horizon_dbhz: 45
  cn0_satellite_sd_db: 0
  cn0_noise_db: 0
  multipath_sigma_m: 0.5
  multipath_tau_s: 1.0
  doppler_sigma_mps: 0.05
  atmosphere_sd_ppm: 600
  atmosphere_tau_s: 2.0
output: {truth_rate_hz: 10}
)";

}  // namespace pednav::test
