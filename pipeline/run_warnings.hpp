// SPDX-License-Identifier: BSD-2-Clause
// The run says when the log does not fit (issue 49 item 3, docs/fusion.md §15): checks of a finished `pednav run`
// (ins or tc) against what a foot-mounted IMU on a walker produces, each with its measured value, the limit it broke
// and what to try. summary.json `warnings` and the report's first lines. Pure functions of the engine's result.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fusion/engine.hpp"
#include "ins/imu.hpp"
#include "ins/imu_spec.hpp"

namespace pednav::pipeline {

struct RunWarning {
  std::string code;     ///< stable identifier (summary.json)
  std::string message;  ///< one line: what was measured against what
  double value = 0.0;   ///< the measured figure
  double limit = 0.0;   ///< the limit it broke
  std::string hint;     ///< what to try
};

/// Limits of the checks (docs/fusion.md §15).
struct RunWarningLimits {
  /// Forward/smoothed disagreement: share of output epochs whose horizontal difference is beyond the 99 % χ²(2)
  /// quantile of its own covariance (P_forward − P_smoothed); 1 % expected for a model that fits.
  double disagreement_max_share = 0.05;
  int disagreement_min_epochs = 20;
  double stance_share_min = 0.05;        ///< stance samples / samples used, when the track is longer than below
  double stance_share_max = 0.90;
  double moving_track_min_m = 10.0;      ///< the stance and gait checks need this much forward track [m]
  double step_length_min_m = 0.2;        ///< median step (half the stance-to-stance stride) [m]
  double step_length_max_m = 2.0;
  double cadence_min_hz = 0.3;           ///< strides per second of walking (stance to stance within max_stride_s)
  double cadence_max_hz = 2.0;
  double max_stride_s = 3.0;             ///< longer stance-to-stance gaps are pauses, not strides
  /// The step and cadence checks read the stances off the output epochs: a stance (0.2-0.5 s) needs a few of them, so
  /// a coarser output (a 1-Hz GNSS-epoch output catches a third of the stances, and strides of any length) skips them.
  double gait_output_interval_max_s = 0.1;
  double gyro_bias_sigmas = 3.0;         ///< final gyro bias estimate beyond this many of the spec's bias σ
  /// ZUPT innovations: share of stances whose first ZUPT's NIS is beyond χ²₃(0.99) (1 % when the model fits; at 10
  /// stances or more a fitting model exceeds 10 % with probability 0.4 % at 10 stances, under 0.1 % from 20 on).
  double zupt_nis_max_share = 0.10;
  long zupt_nis_min_stances = 10;
  /// IMU log checks (imu_log_warnings): the 99.9th percentile of |ω| above this is no foot's (swing peaks 5–15 rad/s;
  /// 40 rad/s = 2300 °/s, beyond most MEMS ranges): a unit declared rad/s for data in °/s.
  double gyro_max_plausible_radps = 40.0;
  /// ... below this while the accelerometer shows steps (its 99th percentile of | |f| − g | above accel_step_mps2):
  /// a foot that steps without turning its sole, i.e. data in rad/s declared °/s.
  double gyro_min_walking_radps = 0.3;
  double accel_step_mps2 = 3.0;
  double rate_min_hz = 20.0;             ///< sample rate from the time column outside this band: a wrong time unit
  double rate_max_hz = 10000.0;
};

/// The checks on the result of one run with the filter's IMU spec (after self-calibration). An empty list: the log
/// fits.
std::vector<RunWarning> run_warnings(const fusion::EngineResult& result, const ins::ImuSpec& spec,
                                     const RunWarningLimits& limits = {});

/// Checks of the IMU log itself against what its configuration declares (issue 49 item 3): gyro rates no foot
/// produces (`gyro_unit`: a unit declared rad/s for °/s data, or the reverse), a sample rate from the time column
/// outside 20 Hz – 10 kHz (`imu_rate`: the time unit). Samples in the engine's units (rad/s, m/s², GPST).
std::vector<RunWarning> imu_log_warnings(const std::vector<ins::ImuSample>& samples, const RunWarningLimits& limits = {});

/// summary.json `warnings`: a JSON array (one object per warning: code, message, value, limit, hint).
nlohmann::ordered_json run_warnings_json(const std::vector<RunWarning>& warnings);

}  // namespace pednav::pipeline
