// `pednav simulate SCENARIO.yaml -o OUT`: runs the simulator and writes truth.csv, imu.csv, rover.obs,
// base.obs, nav.rnx, blunders.csv and config.yaml (each atomically). File formats: docs/sim.md §7.
#pragma once

#include <string>

#include "core/expected.hpp"
#include "io/scenario_config.hpp"
#include "sim/simulator.hpp"

namespace pednav::io {

/// What was written (for the log line and tests).
struct SimulateSummary {
  double duration_s = 0.0;       ///< simulated time span [s]
  double distance_m = 0.0;       ///< route distance walked [m]
  int strides = 0;
  long imu_samples = 0;
  long truth_rows = 0;
  int rover_epochs = 0, base_epochs = 0;
  int blunder_events = 0;
  long saturated_samples = 0;
  double max_gyro_radps = 0.0;   ///< largest exact |omega| [rad/s]
  double wall_s = 0.0;
};

/// truth.csv text: the solution.csv columns up to yaw_deg (IMU truth), then ant_x_m, ant_y_m, ant_z_m, stance,
/// route_m; one row every 1/truth_rate_hz.
std::string format_truth_csv(const sim::Simulation& sim);
/// imu.csv text: gps_week, gps_tow_s, gyro_{x,y,z}_radps, accel_{x,y,z}_mps2 (IMU body frame: x forward,
/// y right, z down).
std::string format_imu_csv(const sim::Simulation& sim);
/// config.yaml text for `pednav run`/`pednav gnss` on the written files (mode gnss until `run` exists).
std::string format_run_config(const sim::Simulation& sim, const ScenarioFile& scenario);

/// Run a scenario and write every output into out_dir (created).
Expected<SimulateSummary> run_simulate_command(const ScenarioFile& scenario, const std::string& out_dir);

}  // namespace pednav::io
