// SPDX-License-Identifier: BSD-2-Clause
// Zero-velocity (stance) detectors for a foot-mounted IMU (SHOE, ARE, MAG, moving variance, HMM), run offline over
// a whole log (post-processing: windows are centred on the sample they decide). docs/zupt.md.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.hpp"
#include "ins/hmm.hpp"
#include "ins/imu.hpp"

namespace pednav::ins {

struct ZuptDetectorOptions {
  /// shoe (Skog et al. 2010 GLRT) | mv (seed 004 eq. 1) | are | mag | hmm (seed 002) | labels (given per sample:
  /// reference or oracle stance labels from the IMU log, to separate detector errors from INS/ZUPT errors)
  std::string detector = "shoe";
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
  /// Gait-adaptive SHOE (docs/zupt.md §1): stance when T_k < max(γ, factor · m_k), m_k = min of T over a centred
  /// window of shoe_adaptive_window_s, and m_k < shoe_adaptive_max (a stance must be near). <= 0: plain SHOE.
  double shoe_adaptive_factor = 0.0;
  double shoe_adaptive_window_s = 0.6;  ///< about half a gait cycle either side at a fast gait [s]
  double shoe_adaptive_max = 1000.0;    ///< largest stance minimum of T accepted (|ω| about 3 rad/s at σω 0.1 rad/s)
  /// The threshold is raised only where the same window holds a swing: max |ω| over it >= this [rad/s]. A foot that
  /// never gets still between vigorous swings is a fast gait's stance; slow motion without swings (pivoting, crawling,
  /// shuffling) is not, and keeps γ (docs/zupt.md §1). <= 0: no condition.
  double shoe_adaptive_min_peak_radps = 0.0;
  // ARE and MAG (Skog et al. 2010 eq. 8, 9), same window W and sigmas as SHOE:
  // ARE T = 1/(σω² W) Σ|ω|² < γ_are; MAG T = 1/(σa² W) Σ(|f| - g)² < γ_mag.
  double are_threshold = 10.0;      ///< γ_are (10 with σω 0.1 rad/s: RMS rate below 0.32 rad/s)
  double mag_threshold = 2.0;       ///< γ_mag (2 with σa 0.5 m/s^2: RMS of |f| - g below 0.71 m/s^2)
  // HMM (seed 002 §3; docs/zupt.md): observations from the gyro axis across the foot, decoded gait states.
  HmmObservationOptions hmm_observations;  ///< axis/sign, smoothing window, grade width
  std::optional<HmmModel> hmm_model;       ///< trained model (hmm.yaml); absent: seed 002 A1 + Table 1
  bool hmm_train_on_log = true;            ///< Baum-Welch on this log's own observations before decoding
  /// Flip the configured axis sign when most first excursions after a rest (push-off) are positive (docs/zupt.md):
  /// a sensor mounted turned by 180° about its vertical axis flips the sign of the across-the-foot rate.
  bool hmm_auto_sign = true;
  int hmm_max_iterations = 200;            ///< Baum-Welch iterations at most
  std::string hmm_decoder = "viterbi";     ///< viterbi (whole log) | forward (online filtering)
  double hmm_decode_floor = 1e-6;          ///< A, B entries raised to this for decoding (unseen symbols)
  /// A stance dwell extends over samples in any grade the (trained) stance state emits with at least this
  /// probability (docs/zupt.md §3); > 1 keeps stance to its observation's own grade.
  double hmm_stance_grade_probability = 0.05;
  /// HMM: a run of at least this many seconds with the smoothed rate in the two grades at zero rate (|r| < w) is
  /// stance whatever state was decoded (docs/zupt.md §3: a long rest is one merged observation that the trained
  /// cycle, which has no D -> D transition, may decode as push-off). <= 0: off.
  double hmm_rest_s = 0.5;
  /// HMM: a stance run that begins less than this after the previous stance run ended, with a push-off decoded in
  /// between, is not stance (seed 004's Δt for the HMM; docs/zupt.md §3): after a push-off the foot must swing and
  /// land first. <= 0: off.
  double hmm_min_swing_s = 0.3;
  /// HMM: stance shortening by the SHOE statistic T (same window, sigmas and γ as `shoe`), a threshold that adapts
  /// to gait speed: in each decoded stance interval only the contiguous run around the minimum T_min of T with
  /// T < max(γ, factor · T_min) is kept, widened to min_stance_s (docs/zupt.md §3). <= 0: off.
  double hmm_refine_factor = 0.0;
  double min_stance_s = 0.04;       ///< shorter stance runs are discarded [s]
  /// Every problem at once, empty when valid ("zupt.mv_threshold_mps2 must be > 0").
  std::vector<std::string> problems() const;
};

/// Per-sample decision.
struct ZuptDecision {
  bool stance = false;
  double statistic = 0.0;  ///< mv: std(|f|) [m/s^2]; shoe, are, mag: T; hmm: smoothed signed axis rate [rad/s]
  int gait_state = -1;     ///< hmm: decoded state per sample (GaitState 0..3), else -1
};

/// HMM post-processing (docs/zupt.md §3): a stance run of `d` that begins less than min_s after the previous kept
/// stance run ended, with a push-off (gait_state kPushOff) in between, is set to swing. Gaps without a push-off (a
/// stance interrupted by a flicker) are left alone.
void drop_stances_right_after_push_off(std::vector<ZuptDecision>& d, const std::vector<ImuSample>& s, double min_s);

/// HMM post-processing (docs/zupt.md §3): each stance run of `d` keeps its contiguous core where the SHOE
/// statistic `t` (one per sample) is below max(γ, hmm_refine_factor · its minimum in the run); a core shorter than
/// min_stance_s is widened towards the smaller T — beyond the run only when the run is a whole step of its own
/// (gait_state heel strike before it, push-off after it, a swing since the previous stance), and never into the
/// neighbouring stance runs. Outside the core the run keeps the samples with T < γ (SHOE's own test), so one
/// footfall may become several stance runs; stance_phases() counts it once.
void refine_hmm_stances(std::vector<ZuptDecision>& d, const std::vector<ImuSample>& s, const std::vector<double>& t,
                        const ZuptDetectorOptions& o);

/// The HMM detector's by-products (for `pednav zupt` and the documentation).
struct HmmDetection {
  std::vector<ZuptDecision> decisions;  ///< one per sample
  GaitObservations observations;        ///< extracted observation sequence
  double sign = 1.0;                    ///< axis sign used (hmm_auto_sign may flip the configured one)
  std::vector<int> obs_states;          ///< decoded state per observation
  HmmModel model;                       ///< model used for decoding (trained on the log if configured)
  BaumWelchResult training;             ///< empty log_likelihood when not trained on the log
};

/// HMM detector of seed 002 over time-ordered samples (GPST): extraction, optional Baum-Welch on the log,
/// decoding, mapping to samples (states_per_sample), stance = state D, short runs dropped.
HmmDetection detect_gait_hmm(const std::vector<ImuSample>& samples, const ZuptDetectorOptions& options);

/// SHOE / GLRT statistic (Skog et al. 2010 eq. 7) per sample over time-ordered samples, window W = shoe_window_s
/// centred on the sample, sigmas shoe_sigma_*; dimensionless.
std::vector<double> shoe_statistic(const std::vector<ImuSample>& samples, const ZuptDetectorOptions& options);

/// Run the configured detector over time-ordered samples (GPST). Returns one decision per sample. Detector
/// `labels` copies `labels` (one 0/1 per sample; statistic = the label; a missing label is swing): the caller
/// checks that the log has them.
std::vector<ZuptDecision> detect_stance(const std::vector<ImuSample>& samples, const ZuptDetectorOptions& options,
                                        const std::vector<uint8_t>* labels = nullptr);

/// Why `labels` cannot be the stance of `n_samples` samples for detector `labels` (none, or a different count);
/// empty when they can or the detector is another one.
std::string stance_label_problem(const ZuptDetectorOptions& options, const std::vector<uint8_t>* labels,
                                 size_t n_samples);

/// Footfalls of a detection, as [first, last] sample indices: the stance runs of `d`, where runs separated only by
/// samples the HMM decoded as stance (gait_state kStance) are one footfall (refine_hmm_stances may split a decoded
/// stance into its still parts). Without HMM states (other detectors) these are the stance runs themselves.
std::vector<std::pair<std::size_t, std::size_t>> stance_phases(const std::vector<ZuptDecision>& d);

/// Samples whose stance may be used by a ZUPT/ZARU update (docs/zupt.md §5): each stance run of `d` without its
/// first and last edge_s (at the onset and the end of a stance a detector's window still flags the foot's last
/// millimetres per second of motion). A run too short for that keeps its central min_core_s (at least one sample),
/// so that no detected stance loses every update. edge_s = 0: the stance flags themselves.
std::vector<bool> zupt_update_samples(const std::vector<ZuptDecision>& d, const std::vector<ImuSample>& s,
                                      double edge_s, double min_core_s);

/// The samples at which a mechanization interval must end so that every stance run keeps a ZUPT (docs/zupt.md §5):
/// the intervals end on a grid of period_ns (ins::IncrementIntegrator), and the ZUPT happens at an interval end whose
/// sample is in `ok` (zupt_update_samples). A run of `ok` samples of one stance in which no sample completes a grid
/// interval (t[k−1] < n·period ≤ t[k]) — a stance shorter than the interval, e.g. 20–50 ms of a running step at 20 Hz
/// — gets its middle `ok` sample flagged: the forward pass closes the interval there (IncrementIntegrator::cut).
std::vector<bool> zupt_forced_interval_ends(const std::vector<ZuptDecision>& d, const std::vector<bool>& ok,
                                            const std::vector<ImuSample>& s, int64_t period_ns);

}  // namespace pednav::ins
