// SPDX-License-Identifier: BSD-2-Clause
// `pednav calibrate CONFIG.yaml -o OUT` (docs/ins.md §10): the IMU log of a configuration (imu.file, imu.format)
// calibrates itself — still periods, gyro bias, noise densities, gravity axis, rate and jitter, saturation, gait —
// into calibration.json, and calibration.yaml: the `imu.spec` mapping and the SHOE threshold that `imu.spec: auto`
// and `zupt.shoe_threshold: auto` would use, each with where it came from.
#pragma once

#include <string>

#include "core/expected.hpp"
#include "io/config.hpp"
#include "pipeline/self_calibration.hpp"

namespace pednav::pipeline {

struct CalibrateResult {
  SelfCalibration self;       ///< spec and threshold as `auto` resolves them
  std::string summary;        ///< the short human summary (also printed by the command)
};

/// Reads the log, calibrates, writes OUT/calibration.json and OUT/calibration.yaml (atomically).
Expected<CalibrateResult> run_calibrate_command(const io::RunConfig& config, const std::string& out_dir);

/// calibration.yaml's text (a YAML document with comments; its `imu.spec` and `zupt` keys read back in a run
/// configuration).
std::string calibration_yaml(const SelfCalibration& s, const std::string& imu_file);

}  // namespace pednav::pipeline
