// SPDX-License-Identifier: BSD-2-Clause
// `pednav zupt CONFIG.yaml -o OUT` (run the configured zero-velocity detector over the IMU log: zupt.csv,
// summary.json, zupt.svg) and `pednav hmm-train CONFIG.yaml... -o hmm.yaml` (Baum-Welch over one or more logs).
#pragma once

#include <string>
#include <vector>

#include "core/expected.hpp"
#include "io/config.hpp"
#include "io/hmm_model_io.hpp"

namespace pednav::pipeline {

/// What `pednav zupt` found.
struct ZuptCommandSummary {
  std::string detector;
  long samples = 0;
  long stance_samples = 0;
  long stance_intervals = 0;        ///< runs of stance samples
  long steps = 0;                   ///< footfalls incl. the initial and final rest (ins::stance_phases; = the
                                    ///< stance runs except where the HMM splits one decoded stance into its still parts)
  long hmm_observations = 0;        ///< hmm only: length of the observation sequence
  int hmm_iterations = 0;           ///< hmm only: Baum-Welch iterations on the log
  ins::HmmModel hmm_model;          ///< hmm only: the model used for decoding
  /// When the log has a stance-label column (imu.format stance.column): the detector's stance samples scored against
  /// the labels — precision = TP / (TP + FP), recall = TP / (TP + FN) over all samples; -1 without labels.
  long label_stance_samples = -1;
  double label_precision = -1.0;
  double label_recall = -1.0;
  double wall_s = 0.0;
};

/// Run the configured detector (config.zupt) over config.imu.file; writes out_dir/zupt.csv (gps_week, gps_tow_s,
/// stance, statistic, hmm_state, hmm_grade), out_dir/summary.json and the detections plot out_dir/zupt.svg (gnuplot).
Expected<ZuptCommandSummary> run_zupt_command(const io::RunConfig& config, const std::string& out_dir);

/// Train the HMM on the IMU logs of `configs` (all with the same hmm extraction keys), starting from the first
/// config's zupt.hmm_model or seed 002's initial model; writes hmm.yaml to out_path.
Expected<io::HmmModelFile> run_hmm_train_command(const std::vector<io::RunConfig>& configs, const std::string& out_path,
                                             int max_iterations);

}  // namespace pednav::pipeline
