// SPDX-License-Identifier: BSD-2-Clause
// The HMM zero-velocity detector's model file (hmm.yaml, written by `pednav hmm-train`) and the mapping of the
// zupt config section onto the detector options. Format: docs/zupt.md §4.
#pragma once

#include <string>
#include <vector>

#include "core/expected.hpp"
#include "ins/hmm.hpp"
#include "ins/zupt_detector.hpp"
#include "io/config.hpp"

namespace pednav::io {

/// Observation settings a model was trained with (stored in hmm.yaml, checked against the run's config).
struct HmmExtractionInfo {
  std::string gyro_axis = "y";          ///< x | y | z | -x | -y | -z
  double smooth_window_s = 0.05;        ///< [s]
  double grade_width_radps = 0.0;       ///< [rad/s] (YAML key grade_width_deg_per_s)
};

/// What hmm-train records next to the model.
struct HmmTrainingInfo {
  std::vector<std::string> logs;        ///< IMU logs trained on
  long observations = 0;
  int iterations = 0;
  bool converged = false;
  double log_likelihood_initial = 0.0;  ///< ln P(O | λ0), summed over the logs
  double log_likelihood_final = 0.0;    ///< ln P(O | λ)
};

/// A model file: λ plus how it was made.
struct HmmModelFile {
  ins::HmmModel model;
  HmmExtractionInfo extraction;
  HmmTrainingInfo training;
};

/// Read and validate hmm.yaml (every problem at once, "file:line: path: what").
Expected<HmmModelFile> read_hmm_model(const std::string& path);
/// hmm.yaml text of a model file.
std::string hmm_model_yaml(const HmmModelFile& file);

/// Parse "x", "-y", ... into (axis index 0..2, sign ±1); false when malformed.
bool parse_gyro_axis(const std::string& text, int& axis, double& sign);

/// Detector options of a validated zupt config section (SI; the HMM model already loaded).
ins::ZuptDetectorOptions zupt_detector_options(const ZuptConfig& config);

}  // namespace pednav::io
