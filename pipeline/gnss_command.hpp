// SPDX-License-Identifier: BSD-2-Clause
// `pednav gnss CONFIG.yaml -o OUT`: GNSS-only epoch-by-epoch least squares (SD with a base, else undifferenced)
// -> gnss.csv, gnss.pos, summary.json (all written atomically). With a base and L1 carrier phase in both files
// (gnss.carrier auto/on): kinematic RTK (fusion/rtk_filter, docs/carrier.md §4); without a base and with L1 phase in
// the rover: the kinematic filter with time-differenced phase (fusion/tdcp_filter, §9). With a reference:
// evaluation.json.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "core/expected.hpp"
#include "gnss/code_smoothing.hpp"
#include "fusion/rtk_filter.hpp"
#include "fusion/tdcp_filter.hpp"
#include "gnss/epoch_matching.hpp"
#include "io/config.hpp"

namespace pednav::pipeline {

/// Counts reported in summary.json.
struct GnssRunSummary {
  int epochs_read = 0, epochs_solved = 0, epochs_with_velocity = 0;
  std::map<std::string, int> not_solved;          ///< reason -> epochs
  std::map<std::string, int> satellites_rejected; ///< reason -> satellite-epochs
  int rover_event_records = 0, base_event_records = 0;
  bool differential = false;
  bool base_position_from_header = false;
  gnss::AgeStats base_age;
  gnss::CodeSmoothingStats smoothing_rover, smoothing_base;  ///< Doppler smoothing of the code (docs/gnss.md "Doppler smoothing of the code")
  double wall_s = 0.0;
  bool carrier = false;                   ///< RTK with L1 carrier phase (docs/carrier.md §4)
  std::string carrier_note;               ///< why the carrier is not used (gnss.carrier: auto)
  fusion::RtkSummary rtk;                 ///< with carrier
  bool tdcp = false;                      ///< no base, L1 phase in the rover: time-differenced phase (docs/carrier.md §9)
  fusion::TdcpSummary tdcp_summary;       ///< with tdcp
  std::optional<nlohmann::json> evaluation;  ///< with a reference
};

/// Run the GNSS-only solution for a loaded configuration and write the outputs into out_dir (created).
Expected<GnssRunSummary> run_gnss_command(const io::RunConfig& config, const std::string& out_dir);

}  // namespace pednav::pipeline
