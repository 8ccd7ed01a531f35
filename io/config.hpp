// SPDX-License-Identifier: BSD-2-Clause
// Run configuration: YAML -> validated options (SI inside; non-SI YAML keys carry their unit suffix).
// The YAML vocabulary is documented in docs/configuration.md (checked against run_config_keys()). Sections live in io/config_<section>.cpp.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "ins/calibration.hpp"
#include "ins/hmm.hpp"
#include "ins/imu_spec.hpp"
#include "fusion/step_velocity.hpp"
#include "io/imu_csv.hpp"

namespace YAML {
class Node;
class Emitter;
}

namespace pednav::io {

class YamlMap;

/// `gnss:` section and the top-level GNSS file keys.
struct GnssConfig {
  std::string rover_obs;                 ///< rover RINEX obs (top-level key rover_obs)
  std::string base_obs;                  ///< base RINEX obs, empty = undifferenced (top-level key base_obs)
  std::vector<std::string> nav;          ///< RINEX nav files, merged (top-level key nav)
  std::optional<Eigen::Vector3d> base_position_ecef_m;  ///< else the base RINEX header (approximate)
  std::vector<std::string> systems{"G"}; ///< G R E C J
  double elevation_mask_rad = 10.0 * 3.14159265358979323846 / 180.0;  ///< key elevation_mask_deg
  double epoch_match_tolerance_s = 0.1;  ///< rover/base epochs closer than this are simultaneous
  double max_base_age_s = 30.0;          ///< older base epochs are not propagated
  double min_cn0_dbhz = 0.0;             ///< signals below are not used
  bool use_doppler = true;               ///< Doppler updates in pednav run
  std::string base_propagation = "ephemeris";  ///< older base epochs: ephemeris (exact geometry) | doppler
  double code_sigma_zenith_m = 0.4;      ///< code noise at zenith and C/N0 >= cn0_ref_dbhz [m] (docs/gnss.md)
  double doppler_sigma_zenith_mps = 0.05;///< range-rate noise at zenith and C/N0 >= cn0_ref_dbhz [m/s]
  double cn0_ref_dbhz = 45.0;            ///< C/N0 above which the noise no longer decreases [dB-Hz]
  double glonass_code_factor = 3.0;      ///< GLONASS code sigma / GPS code sigma (docs/gnss.md)
  double code_smoothing_s = 10.0;        ///< pednav gnss: Doppler smoothing window of the code [s], 0 = off (docs/gnss.md "Doppler smoothing of the code")
  /// k of the weight model's elevation factor sqrt(1 + k (1/sin^2 el - 1)) (docs/gnss.md eq. W1), for the epoch
  /// least squares and the filter's rows alike; 1 = sigma_zenith * c / sin(el).
  double elevation_weight = 1.0;
  /// b of docs/gnss.md eq. W2: the DLL squaring loss at cn0_ref_dbhz, 2 / ((2 − d) T C/N0_ref); 0 = off.
  double code_squaring_loss = 0.0;
  /// L1 carrier phase (docs/carrier.md): auto = used when the rover and base RINEX have L observations; on = required
  /// (an error without them); off = code and Doppler only (the outputs of pednav 0.2).
  std::string carrier = "auto";
  double carrier_sigma_zenith_m = 0.003;     ///< one receiver's phase noise at zenith and C/N0 >= cn0_ref_dbhz [m]
  double carrier_base_age_sigma_mps = 0.003; ///< phase noise added per second of base-epoch age [m/s]
  double rtk_accel_sigma_horizontal_mps2 = 1.0;  ///< pednav gnss RTK: white acceleration √PSD, horizontal [m/s²/√Hz]
  double rtk_accel_sigma_vertical_mps2 = 0.5;    ///< the vertical one
  /// `gnss.ambiguity:` integer resolution (docs/carrier.md §3).
  struct Ambiguity {
    double ratio_threshold = 3.0;
    /// The tight coupling's ratio threshold (`pednav run` with gnss.carrier: on): it holds every validated fix, so it
    /// accepts more strictly (docs/carrier.md §8; chosen on forest_walk_carrier seeds 2-12, docs/results.md).
    double tc_ratio_threshold = 4.0;
    double min_success_rate = 0.999;
    double elevation_mask_deg = 15.0;
    bool partial = true;
    int min_ambiguities = 6;
    int min_lock_epochs = 3;
    bool hold = false;
    int hold_min_epochs = 5;
    double hold_sigma_cycles = 0.01;
    double validation_w = 4.0;
    bool glonass = false;
    /// search | off: GLONASS integers once the inter-frequency phase bias rate of the receiver pair has been found by
    /// search (docs/carrier.md eqs. 3.9-3.11; 0 for two receivers of one type); ignored with glonass: true.
    std::string glonass_ifb = "search";
  } ambiguity;
};

/// `imu:` section.
struct ImuConfig {
  std::string file;
  std::string format_preset;  ///< a preset name from datasets/imu_formats (empty = column map below)
  std::string spec_preset;    ///< IMU noise preset name
  ImuFormat format;           ///< resolved column map (preset or inline; docs/configuration.md "IMU log format")
  ins::ImuSpec spec;          ///< resolved noise model (preset, possibly overridden by inline keys)
  bool has_format = false;    ///< imu.format was given
  bool has_spec = false;      ///< imu.spec was given
  /// `imu.spec: auto`: the spec comes from the log's own calibration at run time (ins::spec_from_calibration,
  /// docs/ins.md §10); `spec` holds it once resolved (pipeline/self_calibration).
  bool spec_auto = false;
  bool spec_defaulted = false;  ///< spec_auto because imu.spec was not given (the default, issue 49)
};

/// `reference:` section.
struct ReferenceConfig {
  std::string file;
  std::string format = "csv";  ///< csv | pos | nmea
  std::vector<int> nmea_qualities;  ///< GGA fix qualities kept (empty: every valid fix), e.g. [4] = RTK fixed
};

/// `zupt:` section.
struct ZuptConfig {
  std::string detector = "shoe";  ///< shoe (Skog et al. 2010) | mv (seed 004 eq. 1) | are | mag | hmm (seed 002)
  std::string form = "D";       ///< D (seed 001 eq. 8) | F (seed 001 eq. 9)
  double mv_window_s = 0.05;              ///< key mv_window_s
  double mv_threshold_mps2 = 0.6;         ///< key mv_threshold_mps2
  double mv_gyro_threshold_radps = 1.5;   ///< key mv_gyro_threshold_deg_per_s
  double min_time_since_step_s = 0.25;    ///< seed 004 eq. 1 Δt
  double shoe_window_s = 0.03;
  double shoe_sigma_accel_mps2 = 0.5;
  double shoe_sigma_gyro_radps = 0.1;     ///< key shoe_sigma_gyro_deg_per_s
  double shoe_threshold = 10.0;
  /// `shoe_threshold: auto`: γ from the log's still floor of the statistic (ins::auto_shoe_threshold), with the
  /// gait-adaptive raise next to a swing unless its keys are set (docs/zupt.md §6); resolved at run time.
  bool shoe_threshold_auto = false;
  bool shoe_threshold_defaulted = false;  ///< auto because neither zupt.shoe_threshold nor imu.spec was given
  /// key shoe_threshold_motion: with shoe_threshold: auto, γ = the statistic at rest + this allowance
  /// (ins::AutoThresholdOptions::motion; docs/zupt.md §6)
  double shoe_threshold_motion = ins::AutoThresholdOptions{}.motion;
  /// key shoe_threshold_two_class_cap: with shoe_threshold: auto, γ is raised to the two-class split of the log's
  /// statistic up to this cap; 0 = off (ins::AutoThresholdOptions::two_class_cap; docs/zupt.md eq. 6.2)
  double shoe_threshold_two_class_cap = ins::AutoThresholdOptions{}.two_class_cap;
  bool edge_s_given = false;               ///< zupt.edge_s was in the file (else `auto` may choose it)
  bool zaru_gate_given = false;            ///< zupt.zaru_gate_probability was in the file
  bool zaru_sigma_given = false;           ///< zupt.zaru_sigma_deg_per_s was in the file
  bool updates = true;                     ///< key updates: false = the detector only segments steps (step velocity)
  double min_stance_s = 0.04;
  double are_threshold = 10.0;            ///< ARE γ (Skog et al. 2010 eq. 8)
  double mag_threshold = 2.0;             ///< MAG γ (Skog et al. 2010 eq. 9)
  std::string hmm_gyro_axis = "y";        ///< x | y | z | -x | -y | -z: the axis across the foot, signed (docs/zupt.md)
  double hmm_smooth_window_s = 0.05;      ///< moving-average window of the HMM observations
  double hmm_grade_width_radps = 60.0 * 3.14159265358979323846 / 180.0;  ///< key hmm_grade_width_deg_per_s
  std::string hmm_model_file;             ///< key hmm_model (pednav hmm-train output); empty: seed 002 Table 1
  std::optional<ins::HmmModel> hmm_model; ///< loaded from hmm_model_file
  bool hmm_train_on_log = true;           ///< Baum-Welch on the processed log before decoding
  bool hmm_auto_sign = true;              ///< try both signs of hmm_gyro_axis, keep the likelier (docs/zupt.md)
  int hmm_max_iterations = 200;
  std::string hmm_decoder = "viterbi";    ///< viterbi | forward
  double hmm_rest_s = 0.5;                ///< rest of at least this long is stance (ins::ZuptDetectorOptions)
  double hmm_min_swing_s = 0.3;           ///< no stance this soon after a stance and a push-off (ins::ZuptDetectorOptions)
  double hmm_refine_factor = 0.0;         ///< stance shortening by SHOE, adaptive threshold (0: off)
  double shoe_adaptive_factor = 0.0;      ///< gait-adaptive SHOE threshold factor (0: off; ins::ZuptDetectorOptions)
  double shoe_adaptive_window_s = 0.6;
  double shoe_adaptive_min_peak_radps = 0.0;  ///< key shoe_adaptive_min_peak_rate_deg_per_s (0: no condition)
  double sigma_mps = 0.02;                ///< ZUPT measurement noise per axis
  double edge_s = 0.02;                   ///< ZUPT/ZARU skip the first and last edge_s of each stance (docs/zupt.md §5)
  bool zaru = true;
  double zaru_sigma_radps = 0.01;         ///< key zaru_sigma_deg_per_s
  double zaru_gate_probability = 0.0;     ///< ZARU innovation gate, χ²(3) quantile probability; 0 = no gate
};

/// `initial:` section (pednav run).
struct InitialConfig {
  std::optional<double> yaw_rad;                 ///< key yaw_deg; absent: heading from motion (tc)
  /// key heading: magnetometer — the initial yaw from the magnetometer columns of imu.format over the levelling
  /// window (docs/fusion.md §8.1); "auto" (default): yaw_deg when given, else heading from motion (tc).
  bool heading_from_magnetometer = false;
  double declination_rad = 0.0;                  ///< key declination_deg: magnetic declination, east positive
  std::optional<Eigen::Vector3d> position_e;     ///< key position_ecef_m or lat_deg/lon_deg/h_m
  double heading_init_distance_m = 30.0;
  double sigma_position_m = 5.0;
  double sigma_velocity_mps = 0.1;
  double sigma_tilt_rad = 2.0 * 3.14159265358979323846 / 180.0;   ///< key sigma_tilt_deg
  double sigma_yaw_rad = 10.0 * 3.14159265358979323846 / 180.0;   ///< key sigma_yaw_deg (configured heading)
};

/// `antenna:` section: IMU (foot) -> antenna (backpack) geometry of the tightly coupled filter.
struct AntennaConfig {
  Eigen::Vector3d lever_arm_ned_m{0.0, 0.0, -1.2};
  /// part fixed in the foot's heading frame (forward, right, down) [m] (docs/fusion.md §14; right foot: [0, -0.1, 0])
  Eigen::Vector3d lever_arm_heading_m = Eigen::Vector3d::Zero();
  double sigma_horizontal_m = 0.4;
  double sigma_vertical_m = 0.2;
  double velocity_sigma_horizontal_mps = 1.0;
  double velocity_sigma_vertical_mps = 0.3;
  std::string velocity_model = "stride_average";  ///< stride_average | foot (docs/fusion.md §13)
  double stride_velocity_sigma_horizontal_mps = 0.3;
  double stride_velocity_sigma_vertical_mps = 0.3;
  /// With antenna states (gnss.carrier: on in tc, docs/carrier.md §10): the foot-to-antenna tie's σ at mid-stance.
  double stance_sigma_horizontal_m = 0.1;
  double stance_sigma_vertical_m = 0.1;
};

/// `clock:` section: differential receiver clock model.
struct ClockConfig {
  double psd_m2_per_s = 1.0;
  double drift_psd_m2_per_s3 = 0.1;
  double jump_threshold_m = 300.0;
};

/// `multipath:` section: code-multipath Gauss-Markov states of the tc filter (docs/consistency.md §3).
struct MultipathConfig {
  bool states = true;               ///< one unit-variance GM state per tracked satellite (tc; on by default)
  double sigma_m = 0.28;            ///< multipath σ at C/N0 >= cn0_ref_dbhz [m] (per receiver)
  double tau_s = 20.0;              ///< correlation time [s]
  double cn0_ref_dbhz = 45.0;       ///< below, σ grows as 10^((ref − C/N0)/20)
  int slots = 12;                   ///< satellites with a state at once
  double reset_gap_s = 20.0;        ///< a satellite unseen for longer restarts its state [s]
};

/// `scale_factors:` section: IMU scale-factor states (the spec's *_scale_sigma, docs/consistency.md §3).
struct ScaleFactorConfig {
  /// unset (the default, or `auto`): scale factors in mode tc, none in mode ins — without GNSS nothing separates a
  /// scale factor from the attitude and velocity errors the ZUPTs see (docs/consistency.md §3.3, §3.4).
  std::optional<bool> states;
  bool gyro = true;     ///< with scale-factor states: also the gyro block (false: accelerometer scale factors only)
  /// Subtract the errors-in-variables bias of the scale-factor updates (docs/consistency.md §3.6).
  bool bias_compensation = true;
};

/// `bias:` section: how the filter models the IMU biases (docs/consistency.md §3.2).
struct BiasConfig {
  /// gauss_markov: one GM state per axis (instability σ, τ) started at the turn-on σ; random_walk: the turn-on
  /// bias a random constant, the instability a random walk of PSD 2σ²/τ; auto: random_walk in mode tc,
  /// gauss_markov in mode ins (docs/consistency.md §3.3).
  std::string model = "auto";
};

/// `saturation:` section: samples at the IMU spec's full scale (ins/saturation.hpp, docs/ins.md §9).
struct SaturationConfig {
  bool repair = true;  ///< reconstruct clipped runs from their neighbours, their σ into the filter's process noise
};

/// `output:` section.
struct OutputConfig {
  double rate_hz = 1.0;                      ///< solution rows per second
  std::vector<std::string> formats{"csv", "pos"};
};

/// Everything one run needs, resolved (paths absolute or relative to the working directory).
struct RunConfig {
  std::string source_file;      ///< the YAML file this came from
  std::string mode = "tc";      ///< tc | ins | gnss
  GnssConfig gnss;
  ImuConfig imu;
  ReferenceConfig reference;
  double mechanization_rate_hz = 20.0;
  ZuptConfig zupt;
  InitialConfig initial;
  AntennaConfig antenna;
  ClockConfig clock;
  double fault_rejection_probability = 0.999;  ///< chi-square test probability of the innovation check
  int fault_rejection_window_epochs = 0;       ///< persistent-fault test window [epochs] (0 or 1: off)
  bool smoother_enabled = true;
  OutputConfig output;
  MultipathConfig multipath;
  ScaleFactorConfig scale_factors;
  BiasConfig bias;
  /// `step_velocity:` seed 000 step-averaged velocity aiding (fusion/step_velocity.hpp; docs/consistency.md §5): the
  /// inverted-pendulum step length over each step's duration against the INS average velocity. Off by default.
  fusion::StepVelocityOptions step_velocity;
  SaturationConfig saturation;
};

/// The IMU error model the filter gets for a configuration (the `auto` defaults resolved by mode).
struct ImuErrorModelChoice {
  bool scale_states = false;      ///< scale-factor states
  bool gyro_scale_states = false; ///< with scale_states: the gyro block too
  bool bias_random_walk = false;  ///< bias: turn-on constant + random walk (else Gauss-Markov)
};
ImuErrorModelChoice imu_error_model_choice(const RunConfig& c);

/// Read and validate a run configuration; every problem is reported at once ("file:line: yaml.path: what").
Expected<RunConfig> load_run_config(const std::string& path);

/// The configured input files that do not exist, one line each naming the key and the path ("reference.file:
/// /x/ref.csv does not exist"): the IMU log, rover/base obs, nav files, reference, HMM model. Checked by
/// `pednav config-check` and before any processing by every command that reads them (none of them computes first
/// and fails at the end).
std::vector<std::string> missing_input_files(const RunConfig& config);
/// Same from YAML text; `source_name` names it in messages, `base_dir` resolves relative paths.
Expected<RunConfig> parse_run_config(const std::string& yaml_text, const std::string& source_name,
                                     const std::string& base_dir);
/// The resolved configuration as YAML (written next to the outputs as config.resolved.yaml).
std::string to_yaml(const RunConfig& config);
/// Every key path the run configuration reader accepts, sorted ("gnss.ambiguity.partial", "imu.format.time.base",
/// "imu.spec.gyro_arw_deg_per_sqrt_hr", ...): what the reader marks as known (anything else is an "unknown key")
/// on probe files that take each of its branches. docs/configuration.md is checked against it.
std::vector<std::string> run_config_keys();

// Section readers (one file each): read keys of `map` into `out`, reporting problems through `map`.
void read_gnss_section(YamlMap& top, GnssConfig& out);
void read_imu_section(YamlMap& top, ImuConfig& out);
void read_filter_section(YamlMap& top, RunConfig& out);
/// Read the ARE/MAG/HMM keys of the zupt section (io/hmm_model_io.cpp; loads zupt.hmm_model).
void read_zupt_hmm_keys(YamlMap& zupt, ZuptConfig& out);
/// Read an IMU column map (keys of docs/configuration.md "IMU log format") from `m` into `out`.
void read_imu_format(YamlMap& m, ImuFormat& out);
/// Read inline IMU spec keys (unit-suffixed, docs/configuration.md "IMU spec") from `m` into `out` (SI).
void read_imu_spec(YamlMap& m, ins::ImuSpec& out);
/// m[key] as an IMU spec: a preset name, or a map {preset: NAME, <read_imu_spec keys>} overriding the preset's values.
/// `preset` holds the default preset on entry ("" = none: a map then starts from ins::ImuSpec{}) and the name used on
/// return; problems (unknown preset or key) go to m's problem list.
void read_imu_spec_entry(YamlMap& m, const std::string& key, ins::ImuSpec& spec, std::string& preset);
/// The inverse of read_imu_spec_entry: the preset's name when `spec` is exactly the preset, else the map
/// {preset: NAME, <every read_imu_spec key>} (config.resolved.yaml reads back to the same spec).
void emit_imu_spec(YAML::Emitter& e, const ins::ImuSpec& spec, const std::string& preset);
/// The inverse of read_imu_format: every key of an inline IMU column map (config.resolved.yaml reads back to the same
/// format; the mounting as the angles it was read from, or as roll/pitch/yaw of R_b_s when that was set alone).
void emit_imu_format(YAML::Emitter& e, const ImuFormat& format);
/// `{preset: NAME, <only the keys whose value differs from the preset's>}` (a flow map for hand-written configs; reads
/// back to the same spec up to the unit conversion's rounding).
std::string imu_spec_flow_yaml(const ins::ImuSpec& spec, const std::string& preset);
/// A built-in IMU format preset (datasets/imu_formats/<name>.yaml), parsed.
Expected<ImuFormat> imu_format_preset(const std::string& name);

}  // namespace pednav::io
