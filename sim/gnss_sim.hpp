// SPDX-License-Identifier: BSD-2-Clause
// Rover and base GNSS observations (GPS L1 C/A code, Doppler, C/N0) of the simulator (docs/sim.md §6).
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
};

/// DLL thermal code noise [m] at C/N0 [dB-Hz] (Kaplan & Hegarty 2006 eq. 7.88, coherent early-minus-late
/// discriminator): sigma = chip * sqrt(B d / (2 cn0) * (1 + 2 / ((2 - d) T cn0))).
double thermal_code_sigma_m(const GnssOptions& options, double cn0_dbhz);
/// Multipath sigma [m] at C/N0: multipath_sigma_m * 10^(max(0, ref - cn0) / 20).
double multipath_sigma_m(const GnssOptions& options, double cn0_dbhz);
/// Range-rate noise [m/s] at C/N0: doppler_sigma_mps * 10^(max(0, ref - cn0) / 20).
double doppler_sigma_mps(const GnssOptions& options, double cn0_dbhz);

/// The code/Doppler weight model of docs/gnss.md eq. W1 that describes this receiver's simulated noise (what a user
/// would configure from the receiver's data sheet; `pednav montecarlo --receiver-weights`, docs/consistency.md §3.8).
/// Eq. W1's C/N0 factor is the DLL thermal noise's own 1/sqrt(C/N0) law, so σ₀ = the thermal σ at the zenith C/N0
/// (the highest the scenario has, used as cn0_ref) and no elevation factor (the simulated noise depends on the
/// elevation only through the C/N0); the DLL's squaring loss as eq. W2's b = 2 / ((2 − d) T C/N0_zenith), so the code
/// σ is the thermal σ at every C/N0. Left out: the Doppler noise's floor at the multipath reference C/N0 (W1 keeps
/// falling up to the zenith C/N0). Multipath is not in it: it is a separate, correlated error (the filter's multipath
/// states).
gnss::WeightModel receiver_weight_model(const GnssOptions& options);

/// Simulate rover and base observations from t_begin to t_end (GPST, epochs on the rate grid) for the given
/// antenna truth, nav data and options; deterministic from `seed`.
GnssSimulation simulate_gnss(const GnssOptions& options, const gnss::NavData& nav, const AntennaFunction& rover,
                             const Eigen::Vector3d& p_base_e, GpsTime t_begin, GpsTime t_end, uint64_t seed);

}  // namespace pednav::sim
