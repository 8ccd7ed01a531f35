// SPDX-License-Identifier: BSD-2-Clause
// The forward engine's option, input and result types (EngineOptions, EngineInputs, EpochOutput, EngineSummary,
// EngineResult, ...): what the entry point fusion/engine.hpp takes and returns, and what the filter's own parts
// (forward runner, GNSS and stance updates, initialization) read, without including the entry point.
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "fusion/ambiguity.hpp"
#include "fusion/step_velocity.hpp"
#include "gnss/carrier.hpp"
#include "gnss/measurement.hpp"
#include "gnss/types.hpp"
#include "ins/error_state.hpp"
#include "ins/imu.hpp"
#include "ins/imu_spec.hpp"
#include "ins/zupt_detector.hpp"

namespace pednav::fusion {

/// Longest window of the persistent-fault test (EngineOptions::fault_window_epochs) [epochs].
inline constexpr int kMaxFaultWindowEpochs = 16;

enum class Mode { kTightlyCoupled, kInsOnly };
enum class ZuptForm { kDynamic /* D, seed 001 eq. 8 */, kFull /* F, seed 001 eq. 9 */ };

/// Antenna velocity model of the Doppler rows (EngineOptions::antenna_velocity_model).
enum class AntennaVelocityModel { kFoot, kStrideAverage };

struct EngineOptions {
  Mode mode = Mode::kTightlyCoupled;
  double mechanization_rate_hz = 20.0;
  ins::ImuSpec spec;
  // ZUPT.
  ins::ZuptDetectorOptions zupt;
  ZuptForm zupt_form = ZuptForm::kDynamic;
  double zupt_sigma_mps = 0.02;         ///< ZUPT measurement noise per axis [m/s]
  double zupt_edge_s = 0.02;            ///< ZUPT/ZARU skip the first and last zupt_edge_s of each stance (docs/zupt.md §5)
  bool zaru = true;                     ///< zero angular-rate update during stance (mean rate of an all-stance interval)
  double zaru_sigma_radps = 0.01;       ///< [rad/s]
  /// ZARU innovation gate: the ZARU rows of an update are dropped when their normalized innovation exceeds the
  /// χ²(3) quantile at this probability — a foot that still rolls during a detected stance (heel-to-toe at
  /// 0.3–1 rad/s) is not at zero rate, and a ZARU would turn that rotation into a gyro bias. 0 = no gate (the
  /// default: on the x-io loops the gate costs more than it saves; docs/fusion.md §5.3, docs/results.md).
  double zaru_gate_probability = 0.0;
  bool zupt_updates = true;             ///< false: the detector only segments steps (step-velocity-only aiding)
  StepVelocityOptions step_velocity;    ///< seed 000 step-averaged velocity aiding (fusion/step_velocity.hpp)
  // Initial state.
  std::optional<Eigen::Vector3d> initial_position_e;  ///< IMU position [m] ECEF (ins mode: required)
  std::optional<double> initial_yaw_rad;              ///< else heading from motion (tc) / error (ins)
  /// Initial yaw from EngineInputs::mag_b averaged over the levelling window, levelled with its roll and pitch,
  /// plus magnetic_declination_rad (east positive); exclusive with initial_yaw_rad (docs/fusion.md §8.1).
  bool heading_from_magnetometer = false;
  double magnetic_declination_rad = 0.0;
  double heading_init_distance_m = 30.0;              ///< walked GNSS distance used to find the heading
  double initial_sigma_pos_m = 5.0;
  double initial_sigma_vel_mps = 0.1;
  double initial_sigma_tilt_rad = 2.0 * 3.14159265358979323846 / 180.0;
  double initial_sigma_yaw_rad = 10.0 * 3.14159265358979323846 / 180.0;
  /// ins mode: carry the initial heading σ outside the filter as a rotation of the trajectory about the start
  /// (docs/fusion.md §5.5); false keeps all of it in P (used by the seed 001 covariance-recursion test).
  bool ins_heading_as_frame = true;
  /// Keep one GnssRowRecord per tested GNSS measurement in EngineResult::gnss_rows (residuals.csv).
  bool record_gnss_rows = false;
  // GNSS.
  std::vector<gnss::System> systems{gnss::System::kGps};
  double elevation_mask_rad = 10.0 * 3.14159265358979323846 / 180.0;
  double min_cn0_dbhz = 0.0;
  gnss::WeightModel weights;
  bool use_doppler = true;
  Eigen::Vector3d lever_arm_n_m{0.0, 0.0, -1.2};  ///< IMU -> antenna, local level NED [m] (foot -> backpack)
  /// IMU -> antenna part fixed in the foot's heading frame (forward, right, down) [m], added to lever_arm_n_m in the
  /// GNSS rows (docs/fusion.md §14, eq. 14.1): a right-foot IMU has the body about half a step width to its left.
  Eigen::Vector3d lever_arm_heading_m = Eigen::Vector3d::Zero();
  double antenna_sigma_horizontal_m = 0.4;   ///< non-rigid arm: antenna offset noise (white) [m]
  double antenna_sigma_vertical_m = 0.2;
  double antenna_velocity_sigma_horizontal_mps = 1.0;  ///< foot vs body velocity at the GNSS epoch [m/s]
  double antenna_velocity_sigma_vertical_mps = 0.3;
  /// What the Doppler rows predict as the antenna (body) velocity (docs/fusion.md §13). kStrideAverage: the foot's
  /// mean velocity over the last gait cycle (fusion/stride_velocity.hpp, eq. 13.1), Jacobian on the attitude error
  /// (eq. 13.2), noise antenna_stride_velocity_sigma_*; kFoot: the foot's instantaneous velocity, Jacobian on the
  /// velocity error, noise antenna_velocity_sigma_* (biased by gait phase: along-track lag).
  AntennaVelocityModel antenna_velocity_model = AntennaVelocityModel::kStrideAverage;
  double antenna_stride_velocity_sigma_horizontal_mps = 0.3;  ///< body vs stride-average foot velocity [m/s]
  double antenna_stride_velocity_sigma_vertical_mps = 0.3;
  /// Estimate gyro and accelerometer scale-factor errors (ins layout blocks scale_gyro, scale_acc with the spec's
  /// *_scale_sigma and scale_tau_s). Off: scale-factor errors are not modelled (docs/consistency.md §3).
  bool estimate_scale_factors = false;
  /// With estimate_scale_factors: also the gyro block (false: the accelerometer block scale_acc only). The gyro
  /// scale states are the ones that diverge on a clipped gyro (docs/consistency.md §3); the accelerometer scale
  /// errors are the ones that make the vertical dishonest (docs/consistency.md §3.2).
  bool estimate_gyro_scale_factors = true;
  /// With estimate_scale_factors: subtract the errors-in-variables bias of the scale-factor updates (the scale
  /// columns of Φ are built from the measured, noisy rate and specific force; docs/consistency.md §3.6).
  bool scale_bias_compensation = true;
  /// With scale_bias_compensation and the smoother: remove the same errors-in-variables bias from the smoother
  /// interval's mean in every component, by regression on the scale states (docs/consistency.md eq. E.7); false:
  /// in the scale rows only (eq. E.6, the smoother of sessions 11-18).
  bool smoother_eiv_regression = true;
  /// IMU bias model of the filter. false: one first-order Gauss-Markov state per axis with the spec's instability σ
  /// and τ, started at the turn-on σ — its variance then decays towards the instability σ within ~τ whether or not
  /// anything observes the bias. true: the turn-on bias is a random constant and the instability a random walk of
  /// the same short-term PSD 2σ²/τ (no decay; conservative beyond τ). docs/error_state.md §3, docs/consistency.md §3.2.
  bool bias_random_walk = false;
  /// Samples at the full scale of the spec's gyro_range / accel_range are reconstructed from their neighbours and
  /// the filter gets the reconstruction's σ as process noise (ins/saturation.hpp, docs/ins.md §9). false: clipped
  /// samples are integrated as they are.
  bool repair_saturation = true;
  /// Code multipath as one unit-variance first-order Gauss-Markov state u_s per tracked satellite (docs/consistency.md
  /// §3): the code error gets σ_mp · u_s, σ_mp = multipath_sigma_m · 10^(max(0, cn0_ref − C/N0)/20) per receiver
  /// (rover and base in quadrature for SD). multipath_sigma_m = 0: no multipath states (code errors white).
  double multipath_sigma_m = 0.0;
  double multipath_tau_s = 20.0;          ///< correlation time of u_s [s]
  double multipath_cn0_ref_dbhz = 45.0;   ///< C/N0 above which σ_mp no longer decreases [dB-Hz]
  int multipath_slots = 12;               ///< states = satellites tracked at once (more are left white, σ inflated)
  /// A satellite's state is reset to a fresh unit variance when it was not measured for longer than this [s]
  /// (re-acquisition: new multipath); shorter gaps keep it, decayed by the Gauss-Markov transition.
  double multipath_reset_gap_s = 20.0;
  double clock_psd_m2_per_s = 1.0;            ///< differential clock random walk PSD [m^2/s]
  double drift_psd_m2_per_s3 = 0.1;           ///< differential drift random walk PSD [m^2/s^3]
  double clock_jump_threshold_m = 300.0;      ///< median innovation above this resets the clock (ms jumps)
  double fault_probability = 0.999;           ///< chi-square(1) probability of the w-test
  /// Persistent-fault test (docs/fusion.md §6.2): code rows are also tested over windows of up to this many
  /// consecutive epochs of their satellite (0 or 1: off; at most kMaxFaultWindowEpochs).
  int fault_window_epochs = 0;
  double max_base_age_s = 30.0;
  std::optional<Eigen::Vector3d> base_position_e;  ///< SD when set and base epochs are given
  /// SD L1 carrier phase after each SD code/Doppler update (docs/carrier.md §8): one SD ambiguity state per
  /// satellite in `ambiguity_slots` slots; integers resolved and validated as in `ambiguity`, then constraining the
  /// filter. false: code and Doppler only (the outputs of pednav 0.2).
  bool carrier = false;
  double carrier_sigma_zenith_m = 0.003;      ///< one receiver's phase σ at zenith, C/N0 ≥ cn0_ref [m] (eq. 1.3)
  double carrier_base_age_sigma_mps = 0.003;  ///< phase noise per second of base age [m/s]
  int ambiguity_slots = 12;               ///< satellites with phase at once (kMaxErrorDim bounds the total)
  /// Antenna states (docs/carrier.md §10): the antenna's own position and velocity error (ECEF, white-acceleration
  /// dynamics), tied to the foot by the non-rigid arm (antenna_sigma_*) and the stride-average velocity
  /// (antenna_stride_velocity_sigma_*) at every rover epoch; the code, Doppler and phase rows measure the antenna
  /// states instead of the foot through the arm. On with `carrier` (the phase needs an antenna that moves smoothly).
  bool antenna_state = false;
  double antenna_accel_sigma_horizontal_mps2 = 1.0;  ///< white acceleration of the antenna, √PSD [m/s²/√Hz]
  double antenna_accel_sigma_vertical_mps2 = 0.5;
  /// The tie at mid-stance (docs/carrier.md eq. 10.2): the body, and the antenna, pass over the stance foot there, so
  /// the arm's walking variation is at its smallest [m] (the inverted-pendulum gait; not tuned).
  double antenna_stance_sigma_horizontal_m = 0.1;
  double antenna_stance_sigma_vertical_m = 0.1;
  gnss::DopplerSlipOptions carrier_slip;
  AmbiguityOptions ambiguity;
  // Output.
  double output_rate_hz = 1.0;
  /// RTS smoothing of the whole run (docs/fusion.md §12): EngineResult::smoothed at the output epochs.
  bool smoother_enabled = true;
  /// Every problem at once.
  std::vector<std::string> problems() const;
};

/// Everything the engine consumes (GPST throughout).
struct EngineInputs {
  const std::vector<ins::ImuSample>* imu = nullptr;
  const gnss::NavData* nav = nullptr;                 ///< tc only
  const std::vector<gnss::ObsEpoch>* rover = nullptr; ///< tc only
  const std::vector<gnss::ObsEpoch>* base = nullptr;  ///< optional (SD)
  /// Stance labels, one 0/1 per IMU sample (io::ImuLog::stance): required by `zupt.detector: labels`.
  const std::vector<uint8_t>* stance_labels = nullptr;
  /// Magnetic field in the body frame, one per IMU sample (io::ImuLog::mag_b, any unit): required by
  /// EngineOptions::heading_from_magnetometer.
  const std::vector<Eigen::Vector3d>* mag_b = nullptr;
  /// GNSS epochs whose time is in this set are skipped (outage masks); satellites of partial outages removed.
  std::function<void(gnss::ObsEpoch&)> gnss_mask;
  /// Test hook: called at the end of every mechanization step with the step's end time (GPST), after its updates
  /// and outputs (tests/fusion/test_allocations.cpp counts heap allocations between calls).
  std::function<void(GpsTime)> on_step;
  /// Progress and cancellation hook (the Python module's progress bar and Ctrl-C): called every kCancelCheckSamples
  /// IMU samples of every pass with the sample's time (GPST); returning true stops the run, which then fails with
  /// kCancelledMessage. Empty: never called (the outputs do not depend on it).
  std::function<bool(GpsTime)> cancel;
};

/// IMU samples between two calls of EngineInputs::cancel.
inline constexpr size_t kCancelCheckSamples = 256;
/// The error message of a run stopped by EngineInputs::cancel.
inline constexpr const char* kCancelledMessage = "cancelled";

/// One output epoch of the forward solution.
struct EpochOutput {
  GpsTime t;
  ins::NavState nav;
  ins::ImuErrors imu;  ///< the IMU error estimates (biases, scale factors) at this epoch, forward or smoothed
  Eigen::Matrix3d cov_p_n = Eigen::Matrix3d::Zero();  ///< position covariance, NED [m^2]
  Eigen::Matrix3d cov_v_n = Eigen::Matrix3d::Zero();
  double sd_yaw_rad = 0.0;
  int n_sats_used = 0, n_sats_rejected = 0;
  bool zupt = false;
  /// With EngineOptions::carrier (docs/carrier.md §6): SolutionStatus of the epoch (fixed, float, code, ins: the last
  /// GNSS epoch's when it is at most 1.5 s old, else ins), the double differences fixed there and their ratio.
  int solution_status = 0;
  int n_fixed_ambiguities = 0;
  double ar_ratio = 0.0;
  /// With EngineOptions::antenna_state: the antenna's position [m] ECEF, velocity [m/s] ECEF and their covariances
  /// NED (antenna.csv, docs/carrier.md §10).
  bool has_antenna = false;
  Eigen::Vector3d ant_p_e = Eigen::Vector3d::Zero();
  Eigen::Vector3d ant_v_e = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_ant_p_n = Eigen::Matrix3d::Zero();
};

/// The IMU errors the forward filter ended with (body axes), their σ, and for the scale factors the total the
/// errors-in-variables compensation subtracted (docs/consistency.md §3.6). Scale entries are zero when the block
/// is not estimated.
struct ImuEstimate {
  ins::ImuErrors value;
  ins::ImuErrors sd;
  Eigen::Vector3d gyro_scale_compensation = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_scale_compensation = Eigen::Vector3d::Zero();
  bool gyro_scale = false;   ///< the gyro scale block was estimated
  bool accel_scale = false;  ///< the accelerometer scale block was estimated
  bool g_sensitivity = false;  ///< the gyro g-sensitivity consider block is in the state (sd.G_g elementwise)
};

/// Counts for summary.json: every input accounted for.
struct EngineSummary {
  long imu_samples = 0;
  long mechanization_steps = 0;
  long zupt_updates = 0;
  long zupt_samples = 0;             ///< samples flagged as stance by the detector
  long zaru_updates = 0;             ///< ZUPTs that carried ZARU rows
  long zaru_rejected = 0;            ///< ZARU rows dropped by the innovation gate (zaru_gate_probability)
  /// ZUPT innovations (docs/fusion.md §15): the NIS vᵀS⁻¹v of the three velocity rows of every ZUPT (S = H P Hᵀ + R
  /// before the update) and of the first ZUPT of each stance, the one that meets the swing's accumulated error; each
  /// χ²(3) for a model that fits. Sums and counts beyond the 99 % quantile (11.34).
  double zupt_nis_sum = 0.0;
  long zupt_nis_above_p99 = 0;
  long zupt_first_of_stance = 0;
  double zupt_first_nis_sum = 0.0;
  long zupt_first_nis_above_p99 = 0;
  /// mechanization intervals closed early at a stance shorter than the interval (ins::zupt_forced_interval_ends)
  long zupt_short_stance_interval_ends = 0;
  long step_velocity_updates = 0;    ///< seed 000 step-velocity updates applied
  long gnss_epochs = 0;              ///< rover epochs read
  long gnss_epochs_used = 0;         ///< epochs with at least one accepted measurement
  long gnss_epochs_skipped_no_base = 0;
  long gnss_epochs_undifferenced_no_base = 0;  ///< SD configured but no base epoch (base stopped): processed undifferenced
  long gnss_epochs_before_start = 0; ///< before initialization / outside the IMU span
  long gnss_epochs_masked = 0;
  long clock_resets = 0;
  long multipath_resets = 0;         ///< multipath states (re)started: a satellite took a slot or returned after a gap
  /// Carrier phase (EngineOptions::carrier, docs/carrier.md §6): summary.json `carrier`.
  struct Carrier {
    long epochs_with_phase = 0, fix_attempts = 0, fixes_rejected_by_validation = 0, wrong_fix_detections = 0;
    long holds = 0, no_free_slot = 0;
    /// Antenna states (docs/carrier.md §10): tie halves inside the consistency gate, and beyond it (noise inflated,
    /// eq. 10.4).
    long antenna_ties = 0, antenna_ties_inflated = 0;
    std::array<long, static_cast<int>(gnss::SlipReason::kCount)> slips{};
    std::map<std::string, long> not_fixed;
  } carrier;
  std::map<std::string, long> code_used_rejected;     ///< "used", "fault", "low_cn0", "no_ephemeris", ...
  std::map<std::string, long> doppler_used_rejected;
  std::string initialization;        ///< how the state was initialized and when
  double heading_fit_rms_m = 0.0;
  std::optional<GpsTime> heading_init_end;  ///< end of the heading-from-motion span (tc without a configured yaw)
  double heading_init_distance_m = 0.0;     ///< distance the INS/ZUPT track walked for it [m] (docs/fusion.md §8)
  double initial_yaw_deg = 0.0;
  /// heading_from_magnetometer: the levelling window's mean field, its norm (in the unit of mag_b) and dip below the
  /// horizontal [deg]; NaN otherwise.
  double magnetometer_field_norm = std::numeric_limits<double>::quiet_NaN();
  double magnetometer_dip_deg = std::numeric_limits<double>::quiet_NaN();
  /// Gyro bias the filter started from [deg/h] (body axes): the first still period's mean rate minus Earth rate when
  /// that window is >= 2 s and consistent with the turn-on bias (docs/ins.md eq. 6.1), else zero.
  Eigen::Vector3d initial_gyro_bias_deg_per_h = Eigen::Vector3d::Zero();
  double still_gyro_bias_d2 = 0.0;   ///< eq. 6.1 of the first still period (0 when shorter than 2 s)
  bool covariance_healthy = true;    ///< false once a health check failed (even if re-initialized afterwards)
  std::string health_message;
  // Accounting and recovery (docs/robustness.md): every IMU sample and rover measurement is used, rejected or skipped,
  // by reason: samples: in.imu size = imu_samples_used + Σ imu_rejected + Σ imu_skipped; measurements (tc):
  // gnss_measurements = Σ code_used_rejected (incl. "used") + Σ gnss_skipped.
  long imu_samples_used = 0;                 ///< samples fed to the filter (from the first still period on)
  long saturated_runs = 0;                   ///< runs of samples at the full scale on one axis (docs/ins.md §9)
  long saturated_runs_reconstructed = 0;     ///< of those, reconstructed from their neighbours
  long saturated_samples = 0;                ///< samples with any axis at the full scale
  double saturation_max_added_deg = 0.0;     ///< largest angle a gyro run's reconstruction added [deg]
  std::vector<std::string> saturation_notes; ///< a sensor whose data exceed its configured range (not checked)
  std::map<std::string, long> imu_rejected;  ///< "non_finite"
  std::map<std::string, long> imu_skipped;   ///< "before_first_still_period", "filter_diverged" (waiting to re-initialize)
  long gnss_measurements = 0;                ///< satellite observations in all rover epochs (tc)
  std::map<std::string, long> gnss_skipped;  ///< not offered to the filter: "outside_imu_span", "masked", ...
  int reinitializations = 0;                 ///< re-initializations from a GNSS epoch solution after divergence
  std::vector<std::string> health_events;    ///< one line per failed health check and per re-initialization
  bool smoothed = false;             ///< the RTS smoother ran (EngineResult::smoothed filled)
  long smoother_records = 0;         ///< stored backward maps (one per output epoch)
  long smoother_bytes = 0;           ///< heap bytes of the stored backward maps + nominal states at the outputs
  std::string smoother_message;      ///< why the smoother did not produce a solution (empty if it ran or is off)
  ImuEstimate imu_estimate;          ///< at the end of the forward pass
};

/// One tested GNSS measurement of the forward filter's w-test (docs/fusion.md §6): what a user needs to audit the
/// fault rejection (RTKLIB's .stat residuals play this role). Filled when EngineOptions::record_gnss_rows is set.
struct GnssRowRecord {
  GpsTime t;                  ///< rover epoch (GPST)
  gnss::SatId sat;
  bool doppler = false;       ///< false: SD (or UD) pseudorange [m]; true: range rate [m/s]
  double innovation = 0.0;    ///< measured − predicted, after the clock terms [m or m/s]
  double sigma = 0.0;         ///< measurement σ of the weight model (without the common antenna terms) [m or m/s]
  double w = 0.0;             ///< Baarda w-statistic in the first test of the epoch (all rows present)
  double mdb = 0.0;           ///< minimal detectable bias in that test: power 80 % at the configured probability [m or m/s]
  bool rejected = false;      ///< excluded by the iterative w-test
  /// w in the last test the row took part in: for a rejected row the test that rejected it, for a used row the final
  /// test (after every exclusion), so |w_final| ≤ the threshold for used rows. w of the first test also carries the
  /// other rows' blunders (Baarda w-statistics are correlated); w_final does not (docs/fusion.md §6.1).
  double w_final = 0.0;
};

struct EngineResult {
  std::vector<GnssRowRecord> gnss_rows;  ///< per tested measurement (only with EngineOptions::record_gnss_rows)
  std::vector<EpochOutput> epochs;    ///< forward filter
  std::vector<EpochOutput> smoothed;  ///< RTS smoothed, same output epochs (empty if the smoother is off)
  EngineSummary summary;
};

}  // namespace pednav::fusion
