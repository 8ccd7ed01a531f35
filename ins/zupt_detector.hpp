// Zero-velocity (stance) detectors for a foot-mounted IMU, run offline over a whole log (post-processing:
// windows are centred on the sample they decide). docs/zupt.md.
#pragma once

#include <string>
#include <vector>

#include "core/expected.hpp"
#include "ins/imu.hpp"

namespace pednav::ins {

struct ZuptDetectorOptions {
  std::string detector = "shoe";    ///< shoe (Skog et al. 2010 GLRT) | mv (seed 004 eq. 1)
  // Moving variance (seed 004 eq. 1): stance when std(|f|) over the window < threshold AND the time since
  // the current step started exceeds min_time_since_step_s.
  double mv_window_s = 0.05;        ///< variance window [s] (seed 004: 3 samples at 100 Hz ~ 0.03 s)
  double mv_threshold_mps2 = 0.6;   ///< threshold on the standard deviation of |f| [m/s^2]
  double mv_gyro_threshold_radps = 1.5;  ///< additionally |omega| below this [rad/s] (<= 0: not used)
  double min_time_since_step_s = 0.25;   ///< seed 004's Δt: no stance this soon after a step started [s]
  // SHOE / GLRT (Skog et al. 2010 eq. 7): T = 1/W sum (|f - g f_mean/|f_mean||^2/σa^2 + |ω|^2/σg^2) < γ.
  double shoe_window_s = 0.03;      ///< W in seconds
  double shoe_sigma_accel_mps2 = 0.5;
  double shoe_sigma_gyro_radps = 0.1;
  double shoe_threshold = 10.0;     ///< γ
  double min_stance_s = 0.04;       ///< shorter stance runs are discarded [s]
  /// Every problem at once, empty when valid ("zupt.mv_threshold_mps2 must be > 0").
  std::vector<std::string> problems() const;
};

/// Per-sample decision.
struct ZuptDecision {
  bool stance = false;
  double statistic = 0.0;  ///< mv: std(|f|) [m/s^2]; shoe: T
};

/// Run the configured detector over time-ordered samples (GPST). Returns one decision per sample.
std::vector<ZuptDecision> detect_stance(const std::vector<ImuSample>& samples, const ZuptDetectorOptions& options);

}  // namespace pednav::ins
