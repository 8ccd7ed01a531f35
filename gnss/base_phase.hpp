// SPDX-License-Identifier: BSD-2-Clause
// The phase arcs of a static base receiver's epochs (docs/carrier.md §2, §5), screened once in time order and shared
// by the GNSS-only RTK filter and the tight coupling: a slip starts a new arc of that satellite; an SD ambiguity
// lives while both its rover and its base arc do.
#pragma once

#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "gnss/carrier.hpp"

namespace pednav::gnss {

/// A static base's phase follows its Doppler across gaps in the recording (the Galway base has 1–14 s gaps), so its
/// gap limit is at least this [s]; its losses of lock are in its LLI.
inline constexpr double kBaseMaxGap_s = 60.0;

struct BasePhaseArcs {
  std::vector<std::vector<int>> arc;  ///< per base epoch, per satellite record: the arc number
  std::map<std::pair<SatId, int>, SlipReason> started_by;  ///< why an arc (after the first) started
  /// Why arc `a` of `sat` started (nullopt for a first arc).
  std::optional<SlipReason> reason(const SatId& sat, int a) const {
    const auto it = started_by.find({sat, a});
    return it == started_by.end() ? std::nullopt : std::optional<SlipReason>(it->second);
  }
};

/// Screen the base epochs (time-ordered) with PhaseSlipScreen, the gap limit raised to kBaseMaxGap_s.
BasePhaseArcs screen_base_phase(const std::vector<ObsEpoch>& base, DopplerSlipOptions o);

}  // namespace pednav::gnss
