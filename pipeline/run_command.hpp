// SPDX-License-Identifier: BSD-2-Clause
// `pednav run CONFIG.yaml -o OUT`: the forward tightly coupled (or INS/ZUPT-only) filter -> solution.csv,
// solution.pos, summary.json, config.resolved.yaml, and evaluation.json when a reference is configured; with
// smoother.enabled also the RTS smoothed smoothed.csv, solution_smoothed.pos and evaluation_smoothed.json.
#pragma once

#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "fusion/engine.hpp"
#include "gnss/types.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "io/solution_writer.hpp"
#include "pipeline/self_calibration.hpp"

namespace pednav::pipeline {

/// Map the validated configuration onto the engine options (IMU spec, ZUPT, GNSS weights, antenna, clock).
fusion::EngineOptions engine_options(const io::RunConfig& config);

/// What `pednav run` rejects in a configuration before it reads any data, one line per problem naming the key
/// ("imu.format: required ...", "fault_rejection.probability must be in (0.5, 1)"); empty when it would start.
/// Checks the IMU format and spec a tc/ins run needs, the format's own problems, the engine options built from every
/// key (fusion::EngineOptions::problems) and initial.heading against the format's magnetometer columns.
/// `pednav config-check` reports the same list, so the two accept the same configurations.
std::vector<std::string> run_config_problems(const io::RunConfig& config);

/// The inputs of a run, read once: the IMU log and, in tc mode, rover/base observations and navigation data, with
/// the engine options (base position from the configuration, else the RINEX header with a warning).
struct RunInputs {
  io::RunConfig config;  ///< the configuration with its `auto` settings resolved from the log (config.resolved.yaml)
  std::optional<SelfCalibration> self_calibration;  ///< what the log said, when a setting was `auto`
  io::ImuLog imu;
  std::optional<gnss::ObsData> rover, base;
  std::optional<gnss::NavData> nav;
  fusion::EngineOptions options;
  /// Engine inputs pointing into this object (valid while it lives and is not moved).
  fusion::EngineInputs engine_inputs() const;
};

/// Read what a `pednav run` (or an outage study) of this configuration needs; errors name the file and key.
Expected<RunInputs> load_run_inputs(const io::RunConfig& config);
/// The same with the IMU log given instead of read from imu.file (the Python module's arrays); null: read it.
Expected<RunInputs> load_run_inputs(const io::RunConfig& config, const io::ImuLog* imu);

/// One solution.csv / smoothed.csv row of an output epoch (IMU position, NED velocity, attitude, σ; pos quality 4
/// with satellites used, else 5).
io::SolutionRow solution_row(const fusion::EpochOutput& e);
/// The antenna row of an output epoch with antenna states (docs/carrier.md §10): antenna position, velocity and σ,
/// the epoch's status; no attitude, no ZUPT flag.
io::SolutionRow antenna_row(const fusion::EpochOutput& e);

/// The configuration as the tightly coupled filter runs it (issue 49 item 8: every command takes any configuration
/// that has what it needs): mode tc as it is; another mode (a file written for `pednav gnss`, or an INS/ZUPT one with
/// GNSS files) with mode tc when it has the IMU log and the GNSS files, else an error naming the configuration, its
/// mode and the missing keys. `command` names the caller in messages ("pednav outage").
Expected<io::RunConfig> tc_config(const io::RunConfig& config, const std::string& command);

/// The configuration `pednav run` runs (before reading anything): mode tc and ins as they are, mode gnss through
/// tc_config (an error when it lacks the IMU log or the GNSS files).
Expected<io::RunConfig> run_config_for_mode(const io::RunConfig& config);

/// Everything `pednav run` computes before it writes a file (the Python module returns it in memory).
struct RunOutputs {
  fusion::EngineResult result;                 ///< forward and smoothed epochs, w-test records (tc), counts
  std::vector<io::SolutionRow> rows;           ///< solution.csv, solution.pos
  std::vector<io::SolutionRow> smoothed_rows;  ///< smoothed.csv (empty when the smoother did not run)
  /// With antenna states (gnss.carrier: on; docs/carrier.md §10): antenna.csv / antenna_smoothed.csv (and .pos), the
  /// antenna's own track; empty otherwise.
  std::vector<io::SolutionRow> antenna_rows, antenna_smoothed_rows;
  nlohmann::ordered_json summary;              ///< summary.json (wall_s: the computation)
  std::string evaluation_json;                 ///< evaluation.json text (with a reference), else empty
  std::string evaluation_smoothed_json;        ///< evaluation_smoothed.json text (with a reference and the smoother)
  io::RunConfig config;                        ///< with its `auto` settings resolved (config.resolved.yaml)
  bool tightly_coupled = false;                ///< mode tc (residuals.csv)
};

/// Run the engine on loaded inputs and build every output of `pednav run` in memory. `cancel` becomes
/// fusion::EngineInputs::cancel (a stopped run fails with fusion::kCancelledMessage); `out_dir` only names the CSV
/// files in the evaluation JSON ("" in memory: "solution.csv").
Expected<RunOutputs> compute_run(const io::RunConfig& config, const RunInputs& data,
                                 std::function<bool(GpsTime)> cancel = {}, const std::string& out_dir = "");

/// Write what compute_run returned as `pednav run` writes it into out_dir (created): solution.csv, solution.pos,
/// config.resolved.yaml, maps, residuals.csv (tc), the smoothed files, evaluation JSON and summary.json (wall_s
/// re-measured from wall0 when given).
Expected<void> write_run_outputs(const io::RunConfig& config, RunOutputs& outputs, const std::string& out_dir,
                                 std::optional<std::chrono::steady_clock::time_point> wall0 = std::nullopt);

/// Run `pednav run` for a loaded configuration and write the outputs into out_dir (created). Mode tc and ins run as
/// they are; a mode gnss configuration runs the tc filter (tc_config) when it has the IMU log and the GNSS files.
Expected<fusion::EngineSummary> run_run_command(const io::RunConfig& config, const std::string& out_dir);

}  // namespace pednav::pipeline
