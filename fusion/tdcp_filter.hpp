// SPDX-License-Identifier: BSD-2-Clause
// GNSS-only kinematic filter of a rover without a base (`pednav gnss` with carrier phase and no base_obs,
// docs/carrier.md §9): antenna position and velocity (the white-acceleration model of the RTK filter), one receiver
// clock per constellation, the clock drift and the clock change between epochs (all three white: restarted every
// epoch), and a clone of the antenna position at the previous epoch (stochastic cloning). Undifferenced code and
// Doppler rows, and time-differenced carrier phase (TDCP) rows that tie the current position to the clone: the
// ambiguity cancels, so a rover alone gets its displacement at carrier precision. Slips by LLI, half-cycle flags,
// integrated Doppler and the epoch's w-test.
#pragma once

#include <Eigen/Core>
#include <array>
#include <map>
#include <optional>
#include <vector>

#include "core/time.hpp"
#include "core/geodesy.hpp"
#include "gnss/carrier.hpp"
#include "gnss/measurement.hpp"
#include "gnss/types.hpp"

namespace pednav::fusion {

struct TdcpOptions {
  std::vector<gnss::System> systems{gnss::System::kGps};
  double elevation_mask_rad = 15.0 * kDegToRad;
  double min_cn0_dbhz = 0.0;
  gnss::WeightModel weights;
  double carrier_sigma_zenith_m = 0.003;     ///< one epoch's phase σ at zenith, C/N0 ≥ cn0_ref [m]
  double accel_sigma_horizontal_mps2 = 1.0;  ///< white acceleration, √PSD [m/s²/√Hz] (horizontal axes)
  double accel_sigma_vertical_mps2 = 0.5;
  double fault_probability = 0.999;          ///< w-test of each row against the epoch (code/Doppler faults, slips)
  bool use_doppler = true;
  bool use_phase = true;                     ///< false: the same filter with code and Doppler only (the comparison)
  gnss::DopplerSlipOptions doppler_slip;
};

/// One epoch of the filter.
struct TdcpEpoch {
  GpsTime time;
  bool ok = false;
  Eigen::Vector3d p_ea_e = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ea_e = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_p_e = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d cov_v_e = Eigen::Matrix3d::Zero();
  /// The antenna's displacement since the previous processed epoch, dt_s earlier (position minus clone, eq. 9.3) [m].
  Eigen::Vector3d displacement_e = Eigen::Vector3d::Zero();
  double dt_s = 0.0;
  int n_sats = 0;      ///< code rows used
  int n_tdcp = 0;      ///< TDCP rows used
  int n_rejected = 0;  ///< code/Doppler rows excluded
};

/// Counters of a run (summary.json `carrier` with mode tdcp).
struct TdcpSummary {
  int epochs = 0, solved = 0, tdcp_epochs = 0, tdcp_rows = 0;
  std::array<int, static_cast<int>(gnss::SlipReason::kCount)> slips{};
  int code_rows_excluded = 0, doppler_rows_excluded = 0;
};

class TdcpFilter {
 public:
  TdcpFilter(const gnss::NavData& nav, const TdcpOptions& o);
  /// Process the next rover epoch (time-ordered). use_code false leaves the code rows out (a code outage: the
  /// pseudorange still tags each satellite's transmit time).
  TdcpEpoch process(const gnss::ObsEpoch& rover, bool use_code = true);
  const TdcpSummary& summary() const { return sum_; }

 private:
  // A satellite's phase at the last processed epoch.
  struct PhaseRecord {
    int arc = 0;
    GpsTime time;
    gnss::SignalAtReceiver signal;  // λΦ [m] in pseudorange_m and the satellite state
    double sigma_m = 0.0;
  };
  const gnss::NavData& nav_;
  TdcpOptions o_;
  // State: p(3) v(3) clone of p at the previous epoch (3), clock per system, drift, clock change per system.
  Eigen::VectorXd x_;
  Eigen::MatrixXd P_;
  bool initialized_ = false;
  GpsTime t_prev_;
  gnss::PhaseSlipScreen screen_;
  std::map<gnss::SatId, int> arc_;
  std::map<gnss::SatId, PhaseRecord> prev_;
  TdcpSummary sum_;

  int n_clk() const { return static_cast<int>(o_.systems.size()); }
  static constexpr int kClone = 6;
  int clock_index(int slot) const { return 9 + slot; }
  int drift_index() const { return 9 + n_clk(); }
  int change_index(int slot) const { return 10 + n_clk() + slot; }
  void predict(double dt);
  void restart_state(int i, double value, double variance);
  void clone_position();
};

}  // namespace pednav::fusion
