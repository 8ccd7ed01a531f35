// SPDX-License-Identifier: BSD-2-Clause
// RINEX reading through RTKLIB 2.4.3 b34 (Debian). The only door to RTKLIB: call from ONE thread
// (RTKLIB keeps static buffers and globals).
#pragma once

#include <string>
#include <vector>

#include "core/expected.hpp"
#include "gnss/types.hpp"

namespace pednav::gnss {

/// Which constellations to read.
struct SystemSelection {
  bool gps = true, glonass = false, galileo = false, beidou = false, qzss = false;
};

/// Read a RINEX 2.1x/3.0x observation file: pseudorange, Doppler, C/N0, LLI on the first frequency
/// (GPS/QZSS L1 C/A, GLONASS G1, Galileo E1, BeiDou B1I). Times are GPST. Fails on a missing, empty or
/// unreadable file or one without observation epochs, with a message naming the file.
Expected<ObsData> read_rinex_obs(const std::string& path, const SystemSelection& systems);

/// Read and merge broadcast ephemerides from RINEX nav files (GPS/QZSS/Galileo/BeiDou Keplerian, GLONASS).
Expected<NavData> read_rinex_nav(const std::vector<std::string>& paths);

}  // namespace pednav::gnss
