// SPDX-License-Identifier: BSD-2-Clause
// A simulator scenario (SI inside; io/scenario_config.* reads it from YAML with unit-suffixed keys).
// The models and their sources are described in docs/sim.md.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "core/time.hpp"
#include "ins/imu_spec.hpp"

namespace pednav::sim {

/// One route waypoint in the local ENU frame of the scenario origin.
struct Waypoint {
  Eigen::Vector3d p_enu_m = Eigen::Vector3d::Zero();  ///< east, north, up of the ground point [m]
  double pause_s = 0.0;                               ///< standing still on arrival [s]
};

/// A timed reference point of the along-a-track mode (the given track is the antenna's).
struct TrackPoint {
  GpsTime t;                                          ///< GPST
  Eigen::Vector3d p_e = Eigen::Vector3d::Zero();      ///< antenna position, ECEF [m]
};

/// Gait of the IMU foot (seed 004: cycle 1.2-1.3 s, stance ~25 %; seed 000: step 0.7 m, T = 0.5 s).
struct GaitOptions {
  double speed_mps = 1.1;            ///< mean walking speed while walking [m/s]
  double cycle_s = 1.2;              ///< gait cycle = one stride of the IMU foot [s]
  double stance_fraction = 0.3;      ///< share of the cycle the foot is flat and still [-]
  double cycle_sd_fraction = 0.03;   ///< per-stride relative SD of swing and stance durations [-]
  double stride_sd_fraction = 0.03;  ///< per-stride relative SD of the stride length [-]
  double clearance_m = 0.12;         ///< peak foot lift during swing [m]
  double pitch_rate_peak_radps = 6.5;///< peak pitch rate at toe-off [rad/s] (per-stride +-10 %)
  double foot_offset_m = 0.1;        ///< IMU foot to the right of the walking line [m]
  double imu_height_m = 0.05;        ///< IMU above the ground when the foot is flat [m]
  double max_turn_per_stride_rad = 1.6;  ///< larger turns at a waypoint are taken as in-place turning strides
};

/// IMU rate and error model (the noise/bias/scale values come from an ins::ImuSpec preset or inline keys).
struct ImuOptions {
  double rate_hz = 100.0;            ///< sample rate [Hz]
  ins::ImuSpec spec;                 ///< noise, bias and scale-factor model, ranges (saturation)
  bool errors = true;                ///< false: the written samples are the exact (noise-free) ones
  double misalignment_sigma_rad = 1e-3;      ///< axis non-orthogonality, per off-diagonal element [rad]
  double gyro_g_sensitivity_sigma = 0.0;     ///< g-sensitive gyro bias, per matrix element [rad/s per m/s^2]
  double gyro_quantum_radps = 0.0;   ///< gyro output resolution [rad/s] (0 = none)
  double accel_quantum_mps2 = 0.0;   ///< accelerometer output resolution [m/s^2] (0 = none)
  /// Mounting of the sensor on the foot: its axes -> the foot's body axes (forward, right, down), R_b_s, as in a
  /// run configuration's imu.format mounting_rpy_deg; the written samples are on the sensor axes (R_b_sᵀ ω_b).
  /// Identity: the sensor is the foot frame (z down at rest).
  Eigen::Matrix3d R_b_s = Eigen::Matrix3d::Identity();
  /// Where the walker carries the IMU: "foot" (the foot-mounted IMU of seeds 001-004) or "hand" (a device held in
  /// front of the body, x along the walk: the body track at hand height with a bob, sway and attitude swing at the
  /// step and stride frequencies and no stance while walking; its GNSS antenna is the device's own; docs/sim.md §9).
  std::string carry = "foot";
};

/// One C/N0 attenuation segment along the route distance of the walker.
struct AttenuationSegment {
  double from_m = 0.0, to_m = 0.0;   ///< route distance span [m]
  std::string type = "open";         ///< open | foliage | indoor (indoor: no signal at all)
  double min_db = 0.0, max_db = 0.0; ///< per-satellite attenuation range [dB] (foliage)
  double tau_s = 10.0;               ///< correlation time of each satellite's attenuation within the range [s]
};

/// A receiver clock: bias, drift and drift random walk (two-state model, Brown & Hwang 2012 §9.3).
struct ClockOptions {
  double bias_s = 0.0;               ///< c*dt at the start / c [s]
  double drift = 0.0;                ///< d(dt)/dt at the start [s/s]
  double drift_rw = 0.0;             ///< drift random walk [s/s/sqrt(s)]
};

/// GNSS observation simulation (rover on the walker, static base).
struct GnssOptions {
  bool enabled = true;
  double rate_hz = 1.0;              ///< epochs per second (tags on the integer GPST grid)
  int satellites = 27;               ///< nominal 24-slot constellation + spares (>= 24, <= 32)
  double elevation_mask_rad = 5.0 * kDegToRad;  ///< below this no signal is tracked
  Eigen::Vector3d base_offset_enu_m{30.0, -20.0, 0.0};  ///< base antenna from the route origin, ENU [m]
  double base_antenna_height_m = 1.5;///< base antenna above the origin's ground height [m]
  double antenna_height_m = 1.6;     ///< rover antenna above the ground under the walker [m]
  double antenna_bob_m = 0.02;       ///< vertical body bob amplitude (twice per stride) [m]
  // C/N0 model: cn0 = zenith - (zenith - horizon)(1 - sin el) + per-satellite offset + noise - attenuation.
  double cn0_zenith_dbhz = 49.0;
  double cn0_horizon_dbhz = 37.0;
  double cn0_satellite_sd_db = 1.5;  ///< constant per-satellite offset SD [dB]
  double cn0_noise_db = 0.5;         ///< white C/N0 noise per epoch [dB]
  double tracking_threshold_dbhz = 18.0;     ///< high-sensitivity tracking limit (seed 004: SiRF III)
  double acquisition_threshold_dbhz = 26.0;  ///< a lost satellite is re-acquired only above this
  std::vector<AttenuationSegment> attenuation;
  // Code noise: DLL thermal noise (Kaplan & Hegarty 2006 eq. 7.88, coherent early-minus-late).
  double dll_bandwidth_hz = 1.0;
  double correlator_spacing_chips = 1.0;
  double integration_time_s = 0.02;
  // Multipath: Gauss-Markov per satellite, sigma grows as the amplitude ratio below cn0_ref.
  double multipath_sigma_m = 0.3;    ///< at C/N0 >= multipath_cn0_ref_dbhz [m]
  double multipath_cn0_ref_dbhz = 45.0;
  double multipath_tau_s = 15.0;
  double doppler_sigma_mps = 0.03;   ///< range-rate noise at C/N0 >= multipath_cn0_ref_dbhz [m/s]
  // Residual single-difference atmosphere: sigma = ppm * baseline / sin(el), Gauss-Markov per satellite.
  double atmosphere_sd_ppm = 2.0;
  double atmosphere_tau_s = 600.0;
  ClockOptions rover_clock{2.0e-4, 5.0e-8, 1.0e-10};
  ClockOptions base_clock{-1.0e-4, -2.0e-8, 5.0e-11};
  // Blunders (cross-correlation / echo-only tracking) on the rover's pseudoranges.
  double blunder_rate = 0.0;         ///< probability per rover satellite-epoch that a blunder starts [-]
  double blunder_min_m = 20.0, blunder_max_m = 100.0;  ///< magnitude range [m], random sign
  double blunder_min_s = 1.0, blunder_max_s = 5.0;     ///< duration range [s]
  // L1 carrier phase (docs/sim.md §8). Off: the observation files carry code, Doppler and C/N0 only, as before.
  bool carrier_phase = false;  ///< write L1C (cycles) with LLI into rover.obs/base.obs, slips into slips.csv
  double atmosphere_sd_iono_fraction = 0.75;         ///< share of the residual SD atmosphere that is ionospheric [-]
  double carrier_tracking_threshold_dbhz = 28.0;     ///< the PLL loses lock below this [dB-Hz]
  double carrier_acquisition_threshold_dbhz = 30.0;  ///< a lost carrier locks again only above this [dB-Hz]
  double pll_bandwidth_hz = 10.0;                    ///< PLL noise bandwidth B_L [Hz] (0: no thermal phase noise)
  double pll_integration_time_s = 0.02;              ///< PLL predetection integration time T [s]
  double carrier_multipath_sigma_m = 0.005;          ///< carrier multipath at C/N0 >= multipath_cn0_ref_dbhz [m]
  double carrier_multipath_tau_s = 10.0;             ///< its Gauss-Markov correlation time [s]
  int carrier_ambiguity_max_cycles = 1000000;        ///< ambiguities are uniform integers in [-max, max] [cycles]
  double carrier_slip_rate_per_s = 0.01;        ///< cycle slips per second at carrier_tracking_threshold_dbhz [1/s]
  double carrier_slip_decade_db = 6.0;          ///< the slip rate falls tenfold every this many dB above it [dB]
  int carrier_slip_max_cycles = 10;             ///< slip size uniform in 1..max cycles, random sign
  double carrier_slip_flagged_fraction = 0.7;   ///< share of the slips that the receiver flags (LLI bit 0) [-]
  double carrier_half_cycle_probability = 0.2;  ///< per (re-)acquisition: half-cycle ambiguity (LLI bit 1)
  double carrier_half_cycle_s = 3.0;            ///< how long the half-cycle offset and its flag last [s]
};

/// Everything one simulation needs.
struct Scenario {
  std::string name;
  uint64_t seed = 1;
  GpsTime start;                     ///< GPST of the first sample (on the integer second)
  Geodetic origin;                   ///< origin of the local ENU route frame (ground)
  std::vector<Waypoint> waypoints;   ///< route (>= 2) unless `track` is given
  std::vector<TrackPoint> track;     ///< along-a-track mode: the given antenna track (>= 2 points)
  double static_start_s = 60.0;      ///< standing still before walking [s]
  double static_end_s = 10.0;        ///< standing still after the last stride [s]
  GaitOptions gait;
  ImuOptions imu;
  GnssOptions gnss;
  double truth_rate_hz = 100.0;      ///< truth.csv rows per second (divides the IMU rate)

  /// Every problem at once (empty when valid): "gait.cycle_s must be in (0.5, 3]".
  std::vector<std::string> problems() const;
};

}  // namespace pednav::sim
