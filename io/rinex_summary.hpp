// SPDX-License-Identifier: BSD-2-Clause
// Human-readable summary of a RINEX observation file (pednav rinex-info).
#pragma once

#include <string>

#include "core/expected.hpp"
#include "gnss/rtklib/rinex.hpp"

namespace pednav::io {

/// Parse "GREJC"-style letters into a system selection; unknown letters are an error.
Expected<gnss::SystemSelection> parse_systems(const std::string& letters);
/// Read the file and describe its span, epochs, interval statistics and per-system satellite counts.
Expected<std::string> summarize_rinex_obs(const std::string& path, const std::string& systems);

}  // namespace pednav::io
