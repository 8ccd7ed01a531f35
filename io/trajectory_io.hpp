// SPDX-License-Identifier: BSD-2-Clause
// Trajectory readers for evaluation: NMEA GGA, RTKLIB .pos, CSV (pednav solution/truth columns and others).
#pragma once

#include <set>
#include <string>

#include "core/expected.hpp"
#include "eval/trajectory.hpp"

namespace pednav::io {

enum class TrajectoryFormat { kAuto, kCsv, kPos, kNmea };

/// GGA fix qualities a configuration may ask for (0 is "invalid", never kept).
inline constexpr int kMinGgaQuality = 1, kMaxGgaQuality = 9;

struct TrajectoryReadOptions {
  TrajectoryFormat format = TrajectoryFormat::kAuto;
  std::set<int> nmea_qualities;  ///< GGA fix qualities to keep (empty: every valid fix, quality >= 1)
  std::string nmea_date;         ///< YYYY-MM-DD of the first GGA (UTC) when the file has no RMC sentence
};

/// What a reader kept and skipped (each skip counted by reason).
struct TrajectoryFile {
  eval::Trajectory trajectory;
  std::string format;  ///< "nmea", "pos", "csv"
  int lines = 0;
  int skipped_quality = 0;   ///< NMEA fixes with a quality not asked for (or 0 = invalid)
  int skipped_checksum = 0;  ///< NMEA sentences with a wrong checksum
  int skipped_empty = 0;     ///< rows without a position
  int skipped_duplicate_time = 0;
};

/// Parse "csv" | "pos" | "nmea" | "auto".
Expected<TrajectoryFormat> parse_trajectory_format(const std::string& name);

/// Read a trajectory; the format is taken from options or guessed from the extension/content.
/// Errors name the file and line: "ref.csv:12: expected 3 numbers in columns x_m, y_m, z_m".
Expected<TrajectoryFile> read_trajectory(const std::string& path, const TrajectoryReadOptions& options);

Expected<TrajectoryFile> read_nmea_gga(const std::string& path, const TrajectoryReadOptions& options);
Expected<TrajectoryFile> read_rtklib_pos(const std::string& path);
/// CSV with a header row. Time: gps_week + gps_tow_s, or GpsCycle + GpsWeek (mod 1024) + "GpsToW [s]".
/// Position: lat_deg, lon_deg, h_m (WGS84) | x_m, y_m, z_m (ECEF) | "Pos ECEF X [m]".. | e_m, n_m, u_m (local frame).
Expected<TrajectoryFile> read_trajectory_csv(const std::string& path);

}  // namespace pednav::io
