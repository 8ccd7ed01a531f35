// SPDX-License-Identifier: BSD-2-Clause
// The simulator's own nominal GPS constellation: Keplerian broadcast ephemerides, nothing downloaded
// (docs/sim.md §5).
#pragma once

#include "core/time.hpp"
#include "gnss/types.hpp"

namespace pednav::sim {

/// A value as it reads back from a RINEX nav field written with "%19.12E" (12 decimals in the mantissa).
double rinex_nav_round(double value);

/// Broadcast ephemerides every 2 h (toe on even hours) covering [t_begin - 2 h, t_end + 2 h] for `satellites`
/// GPS satellites (24 nominal slots, 6 planes x 4, 55 deg, a = 26 559.7 km, after the SPS Performance
/// Standard 2008 Table 3.1-1; spares fill the widest gaps of the planes in turn). Records of one satellite
/// describe one continuous Keplerian orbit. Every value is already rounded as RINEX stores it, so a reader of
/// the written nav file computes the same satellite states. Klobuchar coefficients are set (typical values).
gnss::NavData nominal_gps_constellation(int satellites, GpsTime t_begin, GpsTime t_end, uint64_t seed);

}  // namespace pednav::sim
