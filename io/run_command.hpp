// `pednav run CONFIG.yaml -o OUT`: the forward tightly coupled (or INS/ZUPT-only) filter -> solution.csv,
// solution.pos, summary.json, config.resolved.yaml, and evaluation.json when a reference is configured; with
// smoother.enabled also the RTS smoothed smoothed.csv, solution_smoothed.pos and evaluation_smoothed.json.
#pragma once

#include <string>

#include "core/expected.hpp"
#include "fusion/engine.hpp"
#include "io/config.hpp"

namespace pednav::io {

/// Map the validated configuration onto the engine options (IMU spec, ZUPT, GNSS weights, antenna, clock).
fusion::EngineOptions engine_options(const RunConfig& config);

/// Run `pednav run` for a loaded configuration and write the outputs into out_dir (created).
Expected<fusion::EngineSummary> run_run_command(const RunConfig& config, const std::string& out_dir);

}  // namespace pednav::io
