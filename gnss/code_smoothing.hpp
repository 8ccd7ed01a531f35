// SPDX-License-Identifier: BSD-2-Clause
// Doppler-smoothed pseudoranges (a Hatch filter with the integrated Doppler in place of the carrier phase) for the
// epoch-by-epoch GNSS solution. docs/gnss.md "Doppler smoothing of the code". The carrier phase is not needed, so a loss of lock (LLI) does not
// restart the filter; a data gap, a missing Doppler or a code jump does.
#pragma once

#include <vector>

#include "gnss/types.hpp"

namespace pednav::gnss {

struct CodeSmoothingOptions {
  double window_s = 10.0;          ///< smoothing time constant: N = window_s / epoch interval [s]; 0 disables
  double max_gap_s = 2.5;          ///< a satellite unseen for longer restarts its filter [s]
  double reset_threshold_m = 30.0; ///< |code − predicted smoothed code| above this restarts the satellite [m]
  double clock_jump_m = 1000.0;    ///< a common step of all satellites above this is a receiver clock jump [m]
};

struct CodeSmoothingStats {
  long smoothed = 0;        ///< pseudoranges replaced by a smoothed value (filter older than one epoch)
  long restarts_gap = 0;    ///< filters restarted after a gap or a missing Doppler
  long restarts_jump = 0;   ///< filters restarted after a code jump of one satellite (> reset_threshold_m)
  long clock_jumps = 0;     ///< receiver clock jumps carried into every filter
};

/// Replace each pseudorange by its Doppler-smoothed value, in place, epochs in time order (one receiver):
///   P̃_k = P_k / n + (n − 1)/n · (P̃_{k−1} + ΔR_k),  ΔR_k = −λ (D_{k−1} + D_k)/2 · Δt,  n = min(k − k₀ + 1, N)
/// (docs/gnss.md eq. DS.1). Pseudoranges [m], Doppler [Hz] (range rate = −λD), times GPST.
CodeSmoothingStats smooth_code_with_doppler(std::vector<ObsEpoch>& epochs, const CodeSmoothingOptions& options);

}  // namespace pednav::gnss
