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

}  // namespace pednav::eval
