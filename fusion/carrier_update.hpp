// SPDX-License-Identifier: BSD-2-Clause
// Carrier phase in the tight coupling (docs/carrier.md §8): after an epoch's SD code and Doppler update, the SD L1
// phase rows of the same epoch — one SD ambiguity state per satellite in the filter's ambiguity slots [cycles] —
// with slip screening (LLI, half cycle, gap, integrated Doppler; the base screened once), the w-test against the
// INS-predicted geometry (a phase that fails restarts its ambiguity), integer resolution on double differences
// (fusion/ambiguity) validated by the fixed solution's phase residuals, and the validated integers fed to the filter
// as constraints after hold_min_epochs consecutive fixes; a wrong fix found later restarts every ambiguity.
// Internal to the engine.
#pragma once

#include <Eigen/Core>
#include <map>
#include <vector>

#include "core/time.hpp"
#include "fusion/engine_types.hpp"
#include "fusion/error_state_filter.hpp"
#include "fusion/lever_arm.hpp"
#include "gnss/base_phase.hpp"
#include "gnss/carrier.hpp"
#include "gnss/types.hpp"

namespace pednav::fusion {

/// What the phase update of one epoch did.
struct CarrierEpoch {
  int status = 0;    ///< SolutionStatus as int: fixed, float (phase used) or 0 (no phase row)
  int n_phase = 0;
  int n_fixed = 0;
  double ratio = 0.0;
};

class CarrierUpdater {
 public:
  /// nav: broadcast ephemerides; base: the base epochs (screened once here); o: the engine options (carrier block).
  CarrierUpdater(const gnss::NavData* nav, const std::vector<gnss::ObsEpoch>* base, const EngineOptions& o);

  /// Screen the rover epoch (every epoch, masked or not, so each satellite's phase history stays continuous).
  void screen_rover(const gnss::ObsEpoch& rover);

  /// The phase update of rover epoch `re` (masked, time-tagged) with base epoch `be` (base_index into the base
  /// epochs; be may be a Doppler-propagated copy) whose age is age_s, on filter f at the antenna p_a_e [m, ECEF]
  /// with the lever arm `arm` (its attitude Jacobian), the common antenna position noise C_pos_e [m²], the code σ of
  /// each satellite (for a new ambiguity's variance). pos_col: the first column of the position the rows measure
  /// (the foot's, or the antenna states' of docs/carrier.md §10). Counts into sum.
  CarrierEpoch update(ErrorStateFilter& f, const gnss::ObsEpoch& re, const gnss::ObsEpoch& be, int base_index,
                      double age_s, const Eigen::Vector3d& p_a_e, const LeverArm& arm, const Eigen::Matrix3d& C_pos_e,
                      const std::vector<int>& clock_slot_of_system, const std::map<gnss::SatId, double>& code_sigma,
                      EngineSummary& sum, int pos_col = ins::kPos.offset);

 private:
  const gnss::NavData* nav_;
  const std::vector<gnss::ObsEpoch>* base_;
  const EngineOptions& o_;
  gnss::PhaseSlipScreen rover_screen_;
  std::map<gnss::SatId, int> rover_arc_;
  std::map<gnss::SatId, gnss::SlipReason> rover_reason_;  // reason of the newest rover arc
  gnss::BasePhaseArcs base_arcs_;
  // Ambiguity slots of the filter: satellite, arcs, epochs locked, last epoch [ns], held.
  struct Slot {
    bool used = false;
    gnss::SatId sat;
    int rover_arc = 0, base_arc = 0, lock_epochs = 0;
    int64_t last_ns = 0;
    bool held = false;
  };
  std::vector<Slot> slots_;
  int consecutive_fixes_ = 0;
  void restart_all(ErrorStateFilter& f, gnss::SlipReason why, EngineSummary& sum);
  /// The base receiver's clock drift [m/s] from its epoch's Doppler (median over satellites; 0 without Doppler).
  double base_clock_drift_mps(const gnss::ObsEpoch& base) const;
  int drift_base_index_ = -2;  // base epoch of drift_mps_ (−2: none yet)
  double drift_mps_ = 0.0;
};

}  // namespace pednav::fusion
