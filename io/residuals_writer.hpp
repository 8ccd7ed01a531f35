// SPDX-License-Identifier: BSD-2-Clause
// residuals.csv of `pednav run` (tc mode): one row per GNSS measurement tested by the forward filter's w-test.
#pragma once

#include <string>
#include <vector>

#include "core/expected.hpp"
#include "fusion/engine.hpp"

namespace pednav::io {

/// Write the w-test records (innovation, σ, w, MDB, rejected) to `path` atomically. Columns: gps_week, gps_tow_s (GPST
/// of the rover epoch), sat, type (code | doppler), innovation, sigma, w, mdb (metres for code, m/s for Doppler),
/// rejected (0/1).
Expected<void> write_residuals_csv(const std::string& path, const std::vector<fusion::GnssRowRecord>& records);

}  // namespace pednav::io
