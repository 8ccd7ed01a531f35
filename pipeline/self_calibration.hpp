// SPDX-License-Identifier: BSD-2-Clause
// `imu.spec: auto` and `zupt.shoe_threshold: auto` (docs/ins.md §10, docs/zupt.md §6): the log calibrates itself
// before a run (ins::calibrate_imu), and the configuration gets the IMU model and the SHOE threshold the log shows.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>

#include "core/expected.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "ins/calibration.hpp"

namespace pednav::pipeline {

/// What the log said and what the configuration took from it.
struct SelfCalibration {
  ins::ImuCalibration calibration;
  bool spec_auto = false;
  ins::ImuSpec spec;              ///< the spec resolved for `imu.spec: auto`
  bool threshold_auto = false;
  ins::AutoThreshold threshold;   ///< the SHOE threshold resolved for `zupt.shoe_threshold: auto`
};

/// Resolves the `auto` settings of `config` from `log` in place; nullopt when the configuration has none.
std::optional<SelfCalibration> resolve_self_calibration(io::RunConfig& config, const io::ImuLog& log);

/// The calibration as JSON (calibration.json of `pednav calibrate`, summary.json `self_calibration` of a run).
nlohmann::ordered_json calibration_json(const ins::ImuCalibration& c);
nlohmann::ordered_json self_calibration_json(const SelfCalibration& s);

}  // namespace pednav::pipeline
