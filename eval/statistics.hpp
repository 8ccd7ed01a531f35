// SPDX-License-Identifier: BSD-2-Clause
// Statistics of matched position errors beyond eval/trajectory.hpp: per-segment figures (the run cut into
// consecutive time segments) and vertical figures. Pure functions: no I/O.
#pragma once

#include <vector>

#include "eval/trajectory.hpp"

namespace pednav::eval {

/// Error figures of one time segment [t_start, t_end] (GPST) of a comparison.
struct SegmentStats {
  GpsTime t_start, t_end;
  int epochs = 0;
  double horizontal_rms_m = 0.0, horizontal_max_m = 0.0;
  double vertical_rms_m = 0.0;
  double horizontal_mean_e_m = 0.0, horizontal_mean_n_m = 0.0;  ///< mean error (bias) East / North [m]
};

/// Cut the matched errors into consecutive segments of segment_s seconds (from the first error's time) and
/// give the figures of each non-empty segment.
std::vector<SegmentStats> segment_statistics(const std::vector<EpochError>& errors, double segment_s);

/// Vertical error figures [m]: RMS, mean, standard deviation, 95th percentile of |up error|, max |up error|.
struct VerticalStats {
  double rms_m = 0.0, mean_m = 0.0, std_m = 0.0, p95_abs_m = 0.0, max_abs_m = 0.0;
};
VerticalStats vertical_statistics(const std::vector<EpochError>& errors);

/// Does the solution's σ deserve trust? Over the matched epochs that carry σ (EpochError::sd_enu_m finite and > 0):
/// the share with |e_N| <= 3σ_N and |e_E| <= 3σ_E (99.5 % for a consistent Gaussian filter with uncorrelated N, E),
/// the share with |e_U| <= 3σ_U, the mean of e_E²/σ_E² + e_N²/σ_N² (2 for a consistent filter; the N–E correlation
/// is not in the solution files, so this is the diagonal form of the NEES) and the largest |e|/σ of E or N.
/// Valid only for errors in the solution's own axes (no rotating alignment).
struct ConsistencyStats {
  int epochs = 0;                       ///< matched epochs with a horizontal σ
  double inside_3sigma_pct = 0.0;       ///< N and E inside 3σ [%]
  double inside_3sigma_vertical_pct = 0.0;
  double mean_normalized_sq_horizontal = 0.0;
  double max_normalized_horizontal = 0.0;
};
ConsistencyStats consistency_statistics(const std::vector<EpochError>& errors);

}  // namespace pednav::eval
