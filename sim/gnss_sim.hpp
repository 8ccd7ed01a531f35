// SPDX-License-Identifier: BSD-2-Clause
// Rover and base GNSS observations (GPS L1 C/A code, Doppler, C/N0; L1 carrier phase on request) of the simulator
// (docs/sim.md §6, §8).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "core/time.hpp"
#include "gnss/measurement.hpp"
#include "gnss/types.hpp"
#include "sim/scenario.hpp"

namespace pednav::sim {

/// A receiver antenna's true state at a GPST time: position [m] and velocity [m/s] in ECEF, and the walker's
/// route distance [m] (selects the attenuation segment; 0 for a static base).
struct AntennaTruth {
  Eigen::Vector3d p_e = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_e = Eigen::Vector3d::Zero();
  double route_m = 0.0;
};
using AntennaFunction = std::function<AntennaTruth(GpsTime)>;

/// One pseudorange blunder on one observation (recorded in blunders.csv).
struct BlunderRecord {
  GpsTime t;              ///< epoch tag (GPST receiver time)
  gnss::SatId sat;
  double error_m = 0.0;   ///< added to the pseudorange [m]
  int id = 0;             ///< blunder event number (one event spans several epochs)
};

/// What happened to a carrier phase (slips.csv `kind`; docs/sim.md §8).
enum class CarrierEventKind {
  kLossOfLock,     ///< the carrier is tracked again after a loss of lock: LLI bit 0, a new ambiguity
  kSlipFlagged,    ///< an integer cycle slip with LLI bit 0 set
  kSlipUnflagged,  ///< an integer cycle slip the receiver does not flag
  kHalfCycle,      ///< half-cycle ambiguity after a (re-)acquisition: phase off by +-0.5 cycle while LLI bit 1 is set
};
/// slips.csv name of a kind: loss_of_lock | slip_flagged | slip_unflagged | half_cycle.
const char* carrier_event_name(CarrierEventKind kind);

/// One carrier-phase event (a row of slips.csv).
struct CarrierEvent {
  GpsTime t;          ///< epoch tag (GPST receiver time) of the first observation affected
  bool rover = true;  ///< rover or base receiver
  gnss::SatId sat;
  CarrierEventKind kind = CarrierEventKind::kSlipFlagged;
  double cycles = 0.0;  ///< phase jump [cycles]: ambiguity change (loss of lock, slips) or +-0.5 (half cycle)
};

/// The truth behind one written carrier phase observation (in memory only; the tests' oracle).
struct CarrierTruth {
  GpsTime t;  ///< epoch tag (GPST receiver time)
  bool rover = true;
  gnss::SatId sat;
  double ambiguity_cycles = 0.0;  ///< integer ambiguity N in effect, slips included [cycles]
  double half_cycle = 0.0;        ///< half-cycle offset in the written phase (0 or +-0.5) [cycles]
};

/// True receiver clock at one epoch tag.
struct ClockTruth {
  GpsTime t;
  double rover_bias_s = 0.0, rover_drift = 0.0;  ///< [s], [s/s]
  double base_bias_s = 0.0, base_drift = 0.0;
};

/// The simulated observations and their truth.
struct GnssSimulation {
  gnss::ObsData rover;    ///< epochs with at least one tracked satellite
  gnss::ObsData base;
  Eigen::Vector3d p_base_e = Eigen::Vector3d::Zero();  ///< base antenna, ECEF [m]
  std::vector<BlunderRecord> blunders;
  int blunder_events = 0;
  long rover_sat_epochs = 0;       ///< tracked rover satellite-epochs (the blunder-rate denominator)
  std::vector<ClockTruth> clocks;  ///< every epoch tag
  std::vector<CarrierEvent> carrier_events;  ///< slips.csv (empty unless carrier_phase), in time order
  std::vector<CarrierTruth> carrier_truth;   ///< one per written phase (rover and base), in time order
};

/// Truth atmosphere of the simulated signals (docs/sim.md §6): I = kIonoTruthFactor x Klobuchar, T = kTropoTruthFactor
/// x Saastamoinen, so that undifferenced processing with the broadcast models keeps a model error.
inline constexpr double kIonoTruthFactor = 1.3;
inline constexpr double kTropoTruthFactor = 1.05;

/// DLL thermal code noise [m] at C/N0 [dB-Hz] (Kaplan & Hegarty 2006 eq. 7.88, coherent early-minus-late
/// discriminator): sigma = chip * sqrt(B d / (2 cn0) * (1 + 2 / ((2 - d) T cn0))).
double thermal_code_sigma_m(const GnssOptions& options, double cn0_dbhz);
/// Multipath sigma [m] at C/N0: multipath_sigma_m * 10^(max(0, ref - cn0) / 20).
double multipath_sigma_m(const GnssOptions& options, double cn0_dbhz);
/// Range-rate noise [m/s] at C/N0: doppler_sigma_mps * 10^(max(0, ref - cn0) / 20).
double doppler_sigma_mps(const GnssOptions& options, double cn0_dbhz);

/// PLL thermal phase noise [cycles] at C/N0 [dB-Hz] (Kaplan & Hegarty 2006 ch. 5, PLL thermal noise jitter; docs/sim.md
/// eq. 8.3): sigma = 1/(2 pi) sqrt(B_L / cn0 (1 + 1 / (2 T cn0))), B_L = pll_bandwidth_hz, T = pll_integration_time_s.
double pll_phase_sigma_cycles(const GnssOptions& options, double cn0_dbhz);
/// Carrier multipath sigma [m] at C/N0: carrier_multipath_sigma_m * 10^(max(0, ref - cn0) / 20), at most lambda/12
/// (3 sigma within the single-reflection bound lambda/4; docs/sim.md eq. 8.4).
double carrier_multipath_sigma_m(const GnssOptions& options, double cn0_dbhz);
/// Cycle-slip rate [1/s] at C/N0 (docs/sim.md eq. 8.5): carrier_slip_rate_per_s * 10^(-(cn0 - threshold) / decade_db)
/// with threshold = carrier_tracking_threshold_dbhz.
double carrier_slip_rate_per_s(const GnssOptions& options, double cn0_dbhz);

/// The code/Doppler weight model of docs/gnss.md eq. W1 that describes this receiver's simulated noise (what a user
/// would configure from the receiver's data sheet; `pednav montecarlo --receiver-weights`, docs/consistency.md §3.8).
/// Eq. W1's C/N0 factor is the DLL thermal noise's own 1/sqrt(C/N0) law, so σ₀ = the thermal σ at the zenith C/N0
/// (the highest the scenario has, used as cn0_ref) and no elevation factor (the simulated noise depends on the
/// elevation only through the C/N0); the DLL's squaring loss as eq. W2's b = 2 / ((2 − d) T C/N0_zenith), so the code
/// σ is the thermal σ at every C/N0. Left out: the Doppler noise's floor at the multipath reference C/N0 (W1 keeps
/// falling up to the zenith C/N0). Multipath is not in it: it is a separate, correlated error (the filter's multipath
/// states).
gnss::WeightModel receiver_weight_model(const GnssOptions& options);
/// The phase σ of one receiver at its zenith C/N0 [m]: carrier multipath (eq. 8.4) and PLL thermal noise (eq. 8.3) in
/// quadrature — gnss.carrier_sigma_zenith_m of the data-sheet configuration (with receiver_weight_model's C/N0
/// reference). Both grow below that C/N0 like the weight model's factor; the multipath's 10-s correlation is not in it.
double receiver_carrier_sigma_zenith_m(const GnssOptions& options);

/// Simulate rover and base observations from t_begin to t_end (GPST, epochs on the rate grid) for the given
/// antenna truth, nav data and options; deterministic from `seed`.
GnssSimulation simulate_gnss(const GnssOptions& options, const gnss::NavData& nav, const AntennaFunction& rover,
                             const Eigen::Vector3d& p_base_e, GpsTime t_begin, GpsTime t_end, uint64_t seed);

}  // namespace pednav::sim
