// SPDX-License-Identifier: BSD-2-Clause
// RTKLIB's own broadcast-orbit functions (eph2pos/geph2pos/eph2clk) and its Klobuchar model (ionmodel), exposed
// ONLY as test oracles for gnss/ephemeris.* and gnss/measurement.* (pednav itself computes satellite states and
// broadcast corrections without RTKLIB).
#pragma once

#include <Eigen/Core>

#include <array>

#include "core/geodesy.hpp"
#include "core/time.hpp"
#include "gnss/types.hpp"

namespace pednav::gnss::rtklib_reference {

/// RTKLIB's satellite position [m, ECEF] and clock bias [s] (incl. relativity) from one Keplerian ephemeris at GPST t.
void kepler_position(const KeplerEphemeris& eph, GpsTime t, Eigen::Vector3d& p_es_e, double& clock_bias_s);
/// RTKLIB's GLONASS satellite position [m, PZ-90] and clock bias [s] at GPST t.
void glonass_position(const GlonassEphemeris& eph, GpsTime t, Eigen::Vector3d& p_es_e, double& clock_bias_s);
/// RTKLIB's Klobuchar ionospheric delay on GPS L1 [m] (ionmodel) at GPST t for a receiver at geodetic `llh`
/// (lat/lon [rad], h [m]) and a satellite at azimuth/elevation [rad]; alpha0..3, beta0..3 as broadcast. RTKLIB
/// returns 0 below the horizon (elevation <= 0) and uses its own 2004 default coefficients when all 8 are zero.
double klobuchar_delay_m(const std::array<double, 8>& alpha_beta, GpsTime t, const Geodetic& llh, double azimuth_rad,
                         double elevation_rad);

}  // namespace pednav::gnss::rtklib_reference
