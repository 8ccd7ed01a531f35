// SPDX-License-Identifier: BSD-2-Clause
// Rover/base epoch matching for single differencing (pure: works on time tags only).
#pragma once

#include <vector>

#include "core/time.hpp"
#include "gnss/types.hpp"

namespace pednav::gnss {

/// How a rover epoch is paired with a base epoch.
struct BaseMatch {
  int base_index = -1;  ///< index into the base epochs, -1 = none within max age
  double age_s = 0.0;   ///< rover time - base time [s] (negative: the base epoch is later)
};

/// For each rover epoch the nearest base epoch in time (earlier or later: post-processing); kept when
/// |age| <= max_age_s. Epochs within tolerance_s are "simultaneous". Both lists must be time-ordered.
std::vector<BaseMatch> match_base_epochs(const std::vector<GpsTime>& rover_times,
                                         const std::vector<GpsTime>& base_times, double max_age_s);

/// Propagate a base epoch to time t with each satellite's Doppler: P(t) = P(t_b) - lambda D (t - t_b)
/// (DESIGN.md's base propagation; Doppler-less satellites are dropped). The returned epoch is tagged t.
ObsEpoch propagate_base_with_doppler(const ObsEpoch& base, GpsTime t);

/// Distribution of |age| over the matched rover epochs [s].
struct AgeStats {
  int matched = 0, simultaneous = 0, unmatched = 0;
  double mean_s = 0.0, median_s = 0.0, p95_s = 0.0, max_s = 0.0;
  /// Histogram of |age|: <= tolerance, (tol, 1], (1, 2], (2, 5], (5, 10], (10, 30], > 30 s.
  std::vector<int> histogram = std::vector<int>(7, 0);
};
AgeStats age_statistics(const std::vector<BaseMatch>& matches, double tolerance_s);

}  // namespace pednav::gnss
