// SPDX-License-Identifier: BSD-2-Clause
// GNSS-only kinematic RTK (`pednav gnss` with carrier phase, docs/carrier.md §4): a Kalman filter over the antenna
// position and velocity (white-acceleration model), one SD receiver clock per constellation and the drift (white:
// re-initialized from the code and Doppler each epoch), and one SD ambiguity per satellite [cycles]. SD code, SD
// Doppler and SD L1 phase rows; slips by LLI, Doppler and post-fit residuals; integer resolution on double
// differences (fusion/ambiguity). The same ambiguity code as the tight coupling.
#pragma once

#include <Eigen/Core>
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/time.hpp"
#include "fusion/ambiguity.hpp"
#include "fusion/glonass_ifb.hpp"
#include "gnss/base_phase.hpp"
#include "gnss/carrier.hpp"
#include "gnss/measurement.hpp"
#include "gnss/types.hpp"

namespace pednav::fusion {

struct RtkOptions {
  std::vector<gnss::System> systems{gnss::System::kGps};
  double elevation_mask_rad = 15.0 * kDegToRad;
  double min_cn0_dbhz = 0.0;
  gnss::WeightModel weights;
  double carrier_sigma_zenith_m = 0.003;      ///< one receiver's phase σ at zenith, C/N0 ≥ cn0_ref [m]
  double accel_sigma_horizontal_mps2 = 1.0;   ///< white acceleration, √PSD [m/s²/√Hz] (horizontal axes)
  double accel_sigma_vertical_mps2 = 0.5;
  double base_age_sigma_mps = 0.003;          ///< phase and Doppler-free noise per second of base age [m/s]
  double code_base_age_sigma_mps = 0.05;      ///< the code's [m/s]
  double fault_probability = 0.999;           ///< w-test of the post-fit residuals (code exclusion, phase slips)
  bool use_doppler = true;
  gnss::DopplerSlipOptions doppler_slip;
  AmbiguityOptions ar;
};

/// One epoch of the RTK filter.
struct RtkEpoch {
  GpsTime time;
  SolutionStatus status = SolutionStatus::kNone;
  Eigen::Vector3d p_ea_e = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_ea_e = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_p_e = Eigen::Matrix3d::Zero();
  int n_sats = 0;           ///< satellites with a code row used
  int n_phase = 0;          ///< phase rows used
  int n_rejected = 0;       ///< code/Doppler rows excluded
  int n_fixed = 0;          ///< double differences fixed
  double ratio = 0.0;
  double base_age_s = 0.0;
};

/// Counters of a run (summary.json `carrier`).
struct RtkSummary {
  int epochs = 0, fixed = 0, float_ = 0, code = 0, none = 0;
  std::array<int, static_cast<int>(gnss::SlipReason::kCount)> slips{};
  int fix_attempts = 0, fixes_rejected_by_validation = 0, wrong_fix_detections = 0, holds = 0;
  std::map<std::string, int> not_fixed;  ///< why an attempt did not fix
  std::optional<double> time_to_first_fix_s;
  int code_rows_excluded = 0, doppler_rows_excluded = 0;
  /// With gnss.ambiguity.glonass_ifb: search: the GLONASS inter-frequency phase bias rate β found (eq. 3.11) and
  /// when, in seconds after the first epoch; unset while not found.
  std::optional<double> glonass_ifb_m_per_channel, glonass_ifb_found_s;
  int glonass_ifb_searches = 0, glonass_ifb_votes = 0;
};

class RtkFilter {
 public:
  /// base: the base epochs (time-ordered), screened once for slips here; p_eb_e the base antenna [m, ECEF].
  RtkFilter(const gnss::NavData& nav, const std::vector<gnss::ObsEpoch>& base, const Eigen::Vector3d& p_eb_e,
            const RtkOptions& o);
  /// Process rover epoch `rover` with base epoch base_index (−1: none) whose time differs by age_s.
  RtkEpoch process(const gnss::ObsEpoch& rover, int base_index);
  const RtkSummary& summary() const { return sum_; }
  /// The GLONASS inter-frequency phase bias rate in use [m per channel] (found by search), if any.
  std::optional<double> glonass_ifb_m_per_channel() const { return ifb_.beta_m(); }

 private:
  struct Amb {
    gnss::SatId sat;
    int rover_arc = 0, base_arc = 0;
    int lock_epochs = 0;
    GpsTime last;
    bool held = false;
  };
  struct Row;
  const gnss::NavData& nav_;
  const std::vector<gnss::ObsEpoch>& base_;
  Eigen::Vector3d p_eb_e_;
  RtkOptions o_;
  // State: p(3) v(3) clock per system, drift, ambiguities (cycles) in amb_ order.
  Eigen::VectorXd x_;
  Eigen::MatrixXd P_;
  std::vector<Amb> amb_;
  bool initialized_ = false;
  GpsTime t_prev_;
  std::optional<GpsTime> t_first_;
  gnss::PhaseSlipScreen rover_screen_;
  std::map<gnss::SatId, int> rover_arc_;
  gnss::BasePhaseArcs base_arcs_;
  int consecutive_fixes_ = 0;
  GlonassIfbSearch ifb_;
  RtkSummary sum_;

  int n_clk() const { return static_cast<int>(o_.systems.size()); }
  int clock_index(int slot) const { return 6 + slot; }
  int drift_index() const { return 6 + n_clk(); }
  int amb_index(size_t k) const { return 7 + n_clk() + static_cast<int>(k); }
  void predict(double dt);
  void restart_state(int i, double value, double variance);
  void remove_ambiguity(size_t k);
  int add_ambiguity(const gnss::SatId& sat, double value, double variance);
  void reset_all_ambiguities(gnss::SlipReason why);
};

}  // namespace pednav::fusion
