// SPDX-License-Identifier: BSD-2-Clause
// RINEX 3.04 writers: GPS observation files (C1C, D1C, S1C, and L1C when present) and GPS navigation files (RINEX 3.04
// §A.4, Tables A3 and A6 of the RINEX 3.04 format description, IGS/RTCM 2018). Written atomically.
#pragma once

#include <string>

#include "core/expected.hpp"
#include "gnss/types.hpp"

namespace pednav::io {

/// Header fields of an observation file that ObsData does not carry.
struct RinexObsHeader {
  std::string program = "pednav simulate";
  std::string receiver_type = "PEDNAV SIM HSGPS";
  std::string antenna_type = "PEDNAV SIM PATCH";
  double interval_s = 1.0;  ///< INTERVAL [s]
};

/// RINEX 3.04 observation text of GPS epochs: C1C [m] (F14.3), D1C [Hz], S1C [dB-Hz]; absent values blank. When any
/// observation carries a carrier phase, the types are C1C L1C D1C S1C: L1C [cycles] (F14.3) followed by its
/// loss-of-lock indicator digit (RINEX 3.04 Table A3: bit 0 loss of lock, bit 1 half-cycle ambiguity; blank when 0) and
/// a header line SYS / PHASE SHIFT with 0 for L1C (the GPS L1 reference signal). Without any phase the text is the
/// code-only one. The header date is the first epoch's time (deterministic output). Fails on an empty epoch list.
Expected<std::string> format_rinex_obs(const gnss::ObsData& obs, const RinexObsHeader& header);
/// RINEX 3.04 GPS navigation text (Klobuchar header lines when present, one record per Keplerian ephemeris).
Expected<std::string> format_rinex_nav(const gnss::NavData& nav);

/// format_rinex_obs written atomically to `path`.
Expected<void> write_rinex_obs(const std::string& path, const gnss::ObsData& obs, const RinexObsHeader& header);
/// format_rinex_nav written atomically to `path`.
Expected<void> write_rinex_nav(const std::string& path, const gnss::NavData& nav);

}  // namespace pednav::io
