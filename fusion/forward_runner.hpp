// SPDX-License-Identifier: BSD-2-Clause
// The forward pass of the engine: one time-ordered walk over the IMU samples (saturation repair, bias correction,
// increments at the mechanization rate) that sequences, at each step, the prediction, the ZUPT/ZARU and step updates
// (fusion/stance_updates), the GNSS epochs due (fusion/gnss_update), the health check with re-initialization from a
// GNSS epoch solution after divergence, the output epochs, and the smoother's records; at the end, the backward
// pass (fusion/rts). Internal to the engine; fusion/initialization runs it for the heading from motion, and
// fusion/engine.cpp for the solution.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

#include "core/expected.hpp"
#include "core/time.hpp"
#include "fusion/engine_types.hpp"
#include "fusion/error_state_filter.hpp"
#include "fusion/gnss_update.hpp"
#include "fusion/stance_updates.hpp"
#include "fusion/stride_velocity.hpp"
#include "ins/saturation.hpp"
#include "ins/zupt_detector.hpp"

namespace pednav::fusion {

/// What one forward pass does beyond the filter options.
struct PassOptions {
  bool gnss = true;  ///< process GNSS epochs (false: the INS/ZUPT heading pass)
  std::optional<GpsTime> stop;
  /// The heading pass: each time the IMU has walked the next milestone (walked_milestone_m, then twice that, …) —
  /// horizontal path length of the nominal position over the samples the detector does not flag as stance, so ZUPT
  /// corrections at rest do not count and the distance does not depend on the unknown heading — at_milestone(the
  /// outputs so far, the milestone) is called; the pass stops when it returns true.
  double walked_milestone_m = 0.0;
  std::function<bool(const EngineResult&, double)> at_milestone;
  /// An IMU not on a foot (docs/fusion.md §8.2): the non-holonomic constraint of a hand-held device
  /// (StanceUpdater::hand_nhc_update, eq. 8.4) every this many seconds; 0: off.
  double hand_nhc_interval_s = 0.0;
};

/// Noise of the hand-held non-holonomic constraint (eq. 8.4) [m/s]: a hand's sway and bob (centimetres at the stride
/// and step frequencies: ~0.1 and ~0.3 m/s) and its heading off the walking direction by a few degrees.
inline constexpr double kHandNhcSigmaCrossMps = 0.2, kHandNhcSigmaUpMps = 0.3;

class ForwardRunner {
 public:
  /// decisions: the stance detector's output, one per IMU sample.
  ForwardRunner(const EngineInputs& in, const EngineOptions& o, const std::vector<ins::ZuptDecision>& decisions);

  /// Run the filter from sample `start` with the given initial state; fills result (outputs + summary).
  Expected<void> run(size_t start, const ins::NavState& nav0, const ins::ImuErrors& imu0, const PassOptions& po,
                     EngineResult& result);

  /// The GNSS side (epoch least squares and lever arm, for the initialization).
  const GnssEpochUpdater& gnss() const { return gnss_; }

 private:
  // A GNSS epoch solution kept for a re-initialization: antenna position [m] ECEF at GPST t, satellites in the epoch.
  struct PendingFix {
    GpsTime t;
    Eigen::Vector3d p_ea_e;
    size_t n_sats = 0;
  };
  // Heading-frame uncertainty of an ins-mode run: variance of a rotation about up_e through origin_e [rad², m].
  struct FrameYaw {
    double var_rad2 = 0.0;
    Eigen::Vector3d origin_e = Eigen::Vector3d::Zero();
    Eigen::Vector3d up_e = Eigen::Vector3d::UnitZ();
  };

  // Re-initialization after divergence, called for each IMU sample (time t, GPST; stance: the detector's flag) while
  // waiting: rover epochs up to t are solved by the epoch least squares, the latest solution is kept in `pending`.
  // At a stance with a solution at most kReinitMaxFixAgeS old the filter restarts: position from GNSS (antenna -> IMU,
  // σ >= kReinitSigmaPosM), velocity zero (σ kReinitSigmaVelMps), attitude and IMU errors of `last_stance` (a flat
  // foot again) with a wide heading σ. A restart in mid-swing would take the stance attitude for a foot pitched by
  // tens of degrees. Epochs passed over are counted as skipped. True if re-initialized.
  bool reinitialize(ErrorStateFilter& f, GpsTime t, bool stance, size_t& gi, const ins::InsState& last_stance,
                    std::optional<PendingFix>& pending, EngineSummary& sum);
  // One output epoch from a nominal navigation state and the covariance of its error (forward or smoothed).
  EpochOutput output(const ins::InsState& x, const ErrorMatrix& P, GpsTime t, bool zupt, int used, int rejected) const;
  // The antenna states of an output epoch (docs/carrier.md §10): nominal (or smoothed) position and velocity, ECEF,
  // and the position covariance of the error block at `offset`.
  static void antenna_output(EpochOutput& e, const Eigen::Vector3d& p_e, const Eigen::Vector3d& v_e, const ErrorMatrix& P,
                             int offset);

  const EngineInputs& in_;
  const EngineOptions& o_;
  const std::vector<ins::ZuptDecision>& decisions_;
  std::vector<bool> zupt_ok_;  // stance samples a ZUPT/ZARU may use (zupt_edge_s trimmed; ins::zupt_update_samples)
  std::vector<bool> forced_end_;  // samples that close a mechanization interval early (ins::zupt_forced_interval_ends)
  ins::SaturationRepair saturation_;  // clipped samples repaired once per run (docs/ins.md §9)
  StrideVelocity stride_;             // stride-average foot velocity: the antenna velocity (docs/fusion.md §13)
  FrameYaw frame_;
  GnssEpochUpdater gnss_;
  StanceUpdater stance_;
};

}  // namespace pednav::fusion
