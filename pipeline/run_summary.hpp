// SPDX-License-Identifier: BSD-2-Clause
// The sections of a run's summary.json built from the engine's result (pipeline/run_command.cpp assembles them; keys:
// DESIGN.md, docs/cli.md): the input accounting, the IMU error estimates, the ZUPT counts and innovations, the carrier
// phase. Internal to pipeline/.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "fusion/engine.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "pipeline/run_command.hpp"

namespace pednav::pipeline {

/// `accounting`: read = used + rejected (by reason) + skipped (by reason), for IMU rows and (tc) rover measurements.
nlohmann::ordered_json accounting_json(const io::ImuLog& imu, const RunInputs& data, const fusion::EngineSummary& sum,
                                       bool tc);

/// `imu_estimate`: the forward filter's final IMU errors and their σ (biases; scale factors and g-sensitivity σ when
/// estimated or considered).
nlohmann::json imu_estimate_json(const fusion::ImuEstimate& ie);

/// `zupt`: detector, form, updates, stance samples, ZARU counts, and the ZUPT innovations' NIS (docs/fusion.md §15).
nlohmann::ordered_json zupt_json(const io::RunConfig& c, const fusion::EngineSummary& sum);

/// `carrier` (docs/carrier.md §6): output epochs by status, fix rate, time to first fix, the re-fix time after each
/// span without a fixed epoch of at least 10 s, and the filter's counters.
nlohmann::json carrier_json(const fusion::EngineSummary& sum, const std::vector<fusion::EpochOutput>& epochs);

}  // namespace pednav::pipeline
