// SPDX-License-Identifier: BSD-2-Clause
// The simulator: scenario -> foot truth, IMU samples, antenna truth, rover/base GNSS observations and the
// nominal constellation. Pure: returns data, writes nothing (pipeline/simulate_command.* writes the files).
#pragma once

#include <vector>

#include "core/expected.hpp"
#include "gnss/types.hpp"
#include "ins/imu.hpp"
#include "ins/nav_state.hpp"
#include "sim/gnss_sim.hpp"
#include "sim/imu_errors.hpp"
#include "sim/scenario.hpp"
#include "sim/walk.hpp"

namespace pednav::sim {

/// Everything a simulation produces.
struct Simulation {
  Scenario scenario;
  LocalFrame frame;
  StridePlan plan;
  WalkTruth truth;                           ///< foot truth + exact IMU samples at the IMU rate
  std::vector<ins::ImuSample> imu;           ///< measured IMU samples (errors applied unless disabled)
  ImuErrorTruth imu_errors;
  std::vector<AntennaTruth> antenna;         ///< rover antenna truth at every truth sample
  bool has_gnss = false;
  gnss::NavData nav;                         ///< nominal constellation (as the written nav.rnx reads back)
  GnssSimulation gnss;
};

/// Run a scenario (validated first: every problem in one message).
Expected<Simulation> simulate(const Scenario& scenario);

/// Antenna truth function of a simulation's walker (GPST -> ECEF position/velocity, route distance).
AntennaFunction antenna_function(const Scenario& scenario, const LocalFrame& frame, const StridePlan& plan);

}  // namespace pednav::sim
