// RTKLIB's own broadcast-orbit functions (eph2pos/geph2pos/eph2clk), exposed ONLY as a test oracle for
// gnss/ephemeris.* (pednav itself computes satellite states without RTKLIB).
#pragma once

#include <Eigen/Core>

#include "core/time.hpp"
#include "gnss/types.hpp"

namespace pednav::gnss::rtklib_reference {

/// RTKLIB's satellite position [m, ECEF] and clock bias [s] (incl. relativity) from one Keplerian ephemeris at GPST t.
void kepler_position(const KeplerEphemeris& eph, GpsTime t, Eigen::Vector3d& p_es_e, double& clock_bias_s);
/// RTKLIB's GLONASS satellite position [m, PZ-90] and clock bias [s] at GPST t.
void glonass_position(const GlonassEphemeris& eph, GpsTime t, Eigen::Vector3d& p_es_e, double& clock_bias_s);

}  // namespace pednav::gnss::rtklib_reference
