// SPDX-License-Identifier: BSD-2-Clause
// Simulator scenario files (YAML) -> sim::Scenario, strict (unknown keys, wrong types, out-of-range values are
// errors, all reported at once). Keys: docs/configuration.md "Scenario files".
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "sim/scenario.hpp"

namespace pednav::io {

/// Real GNSS files of the along-a-track mode (written into the output config.yaml instead of simulated ones).
struct RealGnssFiles {
  std::string rover_obs, base_obs;       ///< absolute or relative to the working directory
  std::vector<std::string> nav;
  std::optional<Eigen::Vector3d> base_position_ecef_m;
  std::string reference_file;            ///< the track file (reference of the run)
  std::string reference_format;          ///< csv | pos | nmea
};

/// A scenario file, read.
struct ScenarioFile {
  std::string source_file;
  sim::Scenario scenario;
  std::string imu_spec_preset;           ///< the ins spec preset name used (written into config.yaml)
  std::optional<RealGnssFiles> real_gnss;  ///< along-a-track mode
};

/// Read a scenario from YAML text; `source_name` names it in messages, `base_dir` resolves relative paths.
/// Along-a-track mode reads the track file (io/trajectory_io) here.
Expected<ScenarioFile> parse_scenario(const std::string& yaml_text, const std::string& source_name,
                                      const std::string& base_dir);
/// Read a scenario file.
Expected<ScenarioFile> load_scenario(const std::string& path);
/// Every key path the scenario reader accepts, sorted, list items as "[]" ("route.waypoints[].e_m"): what it marks as
/// known on probe files that take each of its branches (waypoints, both shapes, a track). docs/configuration.md is
/// checked against it.
std::vector<std::string> scenario_config_keys();

}  // namespace pednav::io
