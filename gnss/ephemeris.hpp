// SPDX-License-Identifier: BSD-2-Clause
// Satellite position, velocity, clock bias and clock drift from broadcast ephemerides (pure maths, no RTKLIB).
// GPS/QZSS/Galileo/BeiDou: Keplerian elements, IS-GPS-200 Table 20-IV (+ analytic velocity), BeiDou GEO
// rotation (BDS-SIS-ICD 2.0 §5.2.4.12). GLONASS: RK4 integration of the PZ-90 state vector (GLONASS ICD 5.1
// Appendix J.1). Derivations and constants: docs/gnss.md ("Satellite states").
#pragma once

#include <Eigen/Core>

#include "core/expected.hpp"
#include "core/time.hpp"
#include "gnss/types.hpp"

namespace pednav::gnss {

/// State of one satellite at a (transmit) time, in the ECEF frame of that same instant (no Sagnac rotation).
struct SatState {
  Eigen::Vector3d p_es_e = Eigen::Vector3d::Zero();  ///< position [m], ECEF (WGS84; GLONASS: PZ-90)
  Eigen::Vector3d v_es_e = Eigen::Vector3d::Zero();  ///< velocity [m/s] w.r.t. the rotating ECEF frame
  double clock_bias_s = 0.0;     ///< satellite clock offset incl. relativistic correction [s] (GPST scale)
  double clock_drift_sps = 0.0;  ///< d(clock_bias)/dt [s/s]
  double group_delay_s = 0.0;    ///< broadcast TGD/BGD of the first frequency [s] (undifferenced code only)
  int iode = 0;                  ///< issue of data of the ephemeris used
};

/// Gravitational constant [m^3/s^2] and Earth rotation rate [rad/s] a constellation's ICD uses in its orbits.
struct OrbitConstants {
  double gm_m3ps2;
  double omega_ie_radps;
};
/// The ICD constants for `system` (GPS/QZSS: IS-GPS-200; Galileo OS-SIS-ICD; BeiDou BDS-SIS-ICD; GLONASS ICD).
OrbitConstants orbit_constants(System system);

/// State from one Keplerian ephemeris at GPST time t (transmit time, satellite clock not yet applied to t).
/// Independent of any file reader: the simulator uses it on its own nominal constellation.
SatState kepler_satellite_state(const KeplerEphemeris& eph, GpsTime t);

/// State from one GLONASS ephemeris at GPST time t: RK4 integration (60 s steps) from toe, clock -tau_n + gamma_n*dt.
SatState glonass_satellite_state(const GlonassEphemeris& eph, GpsTime t);

/// Maximum |t - toe| [s] accepted when selecting a broadcast ephemeris of `system`.
double max_ephemeris_age_s(System system);

/// Selects the healthy ephemeris of `sat` with toe closest to t (Galileo: toe <= t + 1 s, i.e. no future
/// ephemeris) within max_ephemeris_age_s and returns its state at GPST time t; an error says why none fits.
Expected<SatState> satellite_state(const NavData& nav, SatId sat, GpsTime t);

}  // namespace pednav::gnss
