// SPDX-License-Identifier: BSD-2-Clause
// Evaluation of a command's solution rows against the configured reference (`reference:`), shared by `pednav run`
// and `pednav gnss`: evaluation JSON written next to the outputs, and the figures for summary.json. Also the carrier
// decisions both commands share.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "fusion/ambiguity.hpp"
#include "gnss/types.hpp"
#include "io/config.hpp"
#include "io/solution_writer.hpp"
#include "io/trajectory_io.hpp"

namespace pednav::pipeline {

/// Read the configuration's reference (format and GGA qualities as configured).
Expected<io::TrajectoryFile> read_configured_reference(const io::RunConfig& c);

/// Compare `rows` (written as `csv_path`) with `reference`, write the evaluation JSON to `json_path` atomically and
/// return the summary figures (horizontal_rms_m, horizontal_max_m, availability_pct, lt5_pct, inside_3sigma_pct).
/// `what` names the solution in the log line.
Expected<nlohmann::json> evaluate_rows(const std::vector<io::SolutionRow>& rows, const io::TrajectoryFile& reference,
                                       const std::string& reference_name, const std::string& csv_path,
                                       const std::string& json_path, const std::string& what);

/// Why the L1 carrier cannot be used with these data (empty: it can): no base, or no phase in the rover or base file.
/// Whether any epoch of `obs` has an L1 carrier phase.
bool has_carrier_phase(const gnss::ObsData& obs);
std::string carrier_unavailable(const io::GnssConfig& g, const gnss::ObsData& rover, const gnss::ObsData* base);

/// The `gnss.ambiguity` section as the engine's options.
fusion::AmbiguityOptions ambiguity_options(const io::GnssConfig& g);

}  // namespace pednav::pipeline
