// SPDX-License-Identifier: BSD-2-Clause
// `pednav simulate SCENARIO.yaml -o OUT`: runs the simulator and writes truth.csv, imu.csv, rover.obs,
// base.obs, nav.rnx, blunders.csv, slips.csv (with carrier phase), config.yaml and config_datasheet.yaml (each
// atomically). File formats: docs/sim.md §7.
#pragma once

#include <string>

#include "core/expected.hpp"
#include "io/config.hpp"
#include "io/scenario_config.hpp"
#include "sim/simulator.hpp"

namespace pednav::pipeline {

/// What was written (for the log line and tests).
struct SimulateSummary {
  double duration_s = 0.0;       ///< simulated time span [s]
  double distance_m = 0.0;       ///< route distance walked [m]
  int strides = 0;
  long imu_samples = 0;
  long truth_rows = 0;
  int rover_epochs = 0, base_epochs = 0;
  int blunder_events = 0;
  bool carrier_phase = false;  ///< L1C written (scenario gnss.carrier_phase)
  int carrier_events = 0;      ///< rows of slips.csv
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
std::string format_run_config(const sim::Simulation& sim, const io::ScenarioFile& scenario);

/// The parts of a simulated sensor's description that a run configuration can take from the scenario instead of
/// `pednav run`'s generic defaults — what a user copies from the data sheets and a tape measure (docs/sim.md §7,
/// docs/consistency.md §3.8–3.10).
struct DataSheetParts {
  bool receiver_weights = false;  ///< code/Doppler weights = the simulated receiver's DLL thermal and Doppler noise, and (with
                                  ///< carrier phase) its phase σ (sim::receiver_carrier_sigma_zenith_m)
  bool lever_arm = false;         ///< antenna lever arm = the simulated walker (antenna over the foot, foot beside the line)
  bool g_sensitivity = false;     ///< the IMU spec's gyro g-sensitivity σ = the simulated one (filter consider states)
  bool multipath = false;         ///< multipath states' σ, τ and C/N0 reference = the simulated code multipath
  static DataSheetParts all() { return {true, true, true, true}; }
};

/// Overwrite the parts of `c` that `parts` names with the scenario's own models (the rest stays as it is).
/// A simulated multipath σ under the configuration's 1 mm minimum turns the multipath states off.
void apply_data_sheet(const sim::Scenario& scenario, const DataSheetParts& parts, io::RunConfig& c);

/// config_datasheet.yaml text: config.yaml in mode tc (ins without GNSS) with every data-sheet part that applies —
/// all four with simulated GNSS; lever arm and g-sensitivity with real GNSS files (the receiver is not simulated);
/// g-sensitivity alone without GNSS. It loads to the configuration `pednav montecarlo --receiver-weights
/// --scenario-lever-arm --g-sensitivity-states --multipath-states` gives its runs.
std::string format_data_sheet_config(const sim::Simulation& sim, const io::ScenarioFile& scenario);

/// Run a scenario and write every output into out_dir (created).
Expected<SimulateSummary> run_simulate_command(const io::ScenarioFile& scenario, const std::string& out_dir);

}  // namespace pednav::pipeline
