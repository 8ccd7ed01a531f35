// SPDX-License-Identifier: BSD-2-Clause
// The GNSS measurement update of one rover epoch (docs/fusion.md §3, §6, §13, §14): base epoch matching (or the
// epoch processed undifferenced when the base stopped), single-differenced (or undifferenced) pseudorange and
// Doppler rows with their Jacobians and C/N0–elevation weights, the code multipath slots, the clock and drift
// initialization and jump detection, the common non-rigid antenna noise, the w-test (fusion/fault_detection.hpp),
// the filter update and the divergence watch. Also the epoch least-squares antenna position used to initialize and
// re-initialize the filter. Internal to the engine.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/time.hpp"
#include "fusion/carrier_update.hpp"
#include "fusion/engine_types.hpp"
#include "fusion/error_state_filter.hpp"
#include "fusion/fault_detection.hpp"
#include "fusion/stride_velocity.hpp"
#include "gnss/epoch_matching.hpp"
#include "gnss/types.hpp"

namespace pednav::fusion {

/// Divergence with a healthy-looking state and covariance (docs/robustness.md): innovations implausible for this many
/// consecutive GNSS epochs, each with at least kImplausibleMinCodeRows code rows of which more than half were rejected.
inline constexpr int kImplausibleEpochs = 10;
inline constexpr int kImplausibleMinCodeRows = 5;

class GnssEpochUpdater {
 public:
  /// Matches rover and base epochs once (SD when a base and its position are given) and sizes the per-epoch
  /// buffers for the largest rover epoch.
  GnssEpochUpdater(const EngineInputs& in, const EngineOptions& o);

  /// IMU -> antenna lever arm (EngineOptions::lever_arm_n_m) resolved in ECEF at position p_e [m].
  Eigen::Vector3d lever_e(const Eigen::Vector3d& p_e) const;

  /// Epoch least-squares antenna position [m] ECEF of rover epoch `rover_index`, started at p_init (used for
  /// initialization, the heading fit and re-initialization). allow_undifferenced: an epoch without a base epoch is
  /// solved undifferenced instead of skipped.
  std::optional<Eigen::Vector3d> lsq_position(size_t rover_index, const Eigen::Vector3d& p_init,
                                              bool allow_undifferenced = false) const;

  /// SD (or UD) pseudorange + Doppler update of `f` with rover epoch gi, processed at mechanization epoch
  /// t_proc >= the epoch. stride: the foot's stride-average velocity (the antenna velocity of the Doppler rows with
  /// AntennaVelocityModel::kStrideAverage, docs/fusion.md eq. 13.1). clock_initialized: false until the clocks were set from an
  /// epoch (set here). used_out / rejected_out: code rows used / rejected in the epoch. records: residuals.csv rows.
  void update(ErrorStateFilter& f, size_t gi, GpsTime t_proc, const StrideVelocity& stride,
              bool& clock_initialized, EngineSummary& sum, int& used_out, int& rejected_out,
              std::vector<GnssRowRecord>* records);

  /// Consecutive GNSS epochs with most of their code rows rejected (divergence watch).
  int implausible_streak() const { return implausible_streak_; }
  /// Start over after a (re-)initialization: no streak, no fault history.
  void restart(bool clear_fault_history) {
    implausible_streak_ = 0;
    if (clear_fault_history) faults_.clear_history();
  }
  /// Rows one epoch can have (code + Doppler of the largest rover epoch): capacity of the row buffer.
  size_t row_capacity() const { return rows_.capacity(); }
  /// Capacity of the fault history (no allocation on the per-epoch path).
  void reserve_fault_history() { faults_.reserve(); }
  /// The carrier-phase outcome of the last GNSS epoch (status 0 without carrier) and that epoch's time.
  const CarrierEpoch& last_carrier() const { return last_carrier_; }
  GpsTime last_carrier_time() const { return last_carrier_time_; }

 private:
  const EngineInputs& in_;
  const EngineOptions& o_;
  std::vector<gnss::BaseMatch> matches_;
  bool sd_ = false;
  std::optional<bool> last_sd_;  // differencing of the last processed GNSS epoch (SD or undifferenced)
  int implausible_streak_ = 0;   // consecutive GNSS epochs with most code rows rejected
  FaultDetector faults_;
  // Per-epoch buffers, reused (their capacity persists: no heap allocation after the first epochs).
  gnss::ObsEpoch re_;
  std::vector<GnssRow> rows_;
  std::vector<std::vector<double>> code_res_by_slot_;
  std::vector<double> doppler_res_;
  std::vector<int> active_;
  std::optional<CarrierUpdater> carrier_;  // EngineOptions::carrier with a base (docs/carrier.md §8)
  CarrierEpoch last_carrier_;
  GpsTime last_carrier_time_;
  std::map<gnss::SatId, double> code_sigma_;  // this epoch's code σ per satellite with a code row
};

}  // namespace pednav::fusion
