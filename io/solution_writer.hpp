// SPDX-License-Identifier: BSD-2-Clause
// Solution writers shared by `pednav gnss` and `pednav run`: solution.csv columns of DESIGN.md and the
// RTKLIB solution format (.pos, lat/lon/height, readable by rtkplot). Written through io/atomic_file.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "core/time.hpp"

namespace pednav::io {

/// One output epoch. Optional fields are written as empty CSV cells.
struct SolutionRow {
  GpsTime time;                                         ///< GPST
  Eigen::Vector3d p_e = Eigen::Vector3d::Zero();        ///< position [m], ECEF (antenna or IMU, as the caller says)
  std::optional<Eigen::Vector3d> v_n;                   ///< velocity NED [m/s]
  std::optional<Eigen::Vector3d> rpy_deg;               ///< roll, pitch, yaw [deg]
  Eigen::Matrix3d cov_p_n = Eigen::Matrix3d::Zero();    ///< position covariance NED [m^2]
  std::optional<double> sd_yaw_deg;
  int n_sats_used = 0, n_sats_rejected = 0;
  std::optional<bool> zupt;
  int pos_quality = 5;  ///< RTKLIB Q: 1 fix, 2 float, 4 DGPS, 5 single
  double age_s = 0.0;   ///< differential age [s] (.pos column)
  std::optional<double> hdop, pdop;  ///< extra CSV columns (after the DESIGN.md ones)
  /// With carrier phase (docs/carrier.md §6): fixed | float | code | ins; the columns solution_status,
  /// n_fixed_ambiguities, ar_ratio follow pdop when any row of a file has a status.
  const char* solution_status = nullptr;
  int n_fixed_ambiguities = 0;
  double ar_ratio = 0.0;  ///< also the .pos ratio column
};

/// The DESIGN.md solution.csv header (+ hdop, pdop; + solution_status, n_fixed_ambiguities, ar_ratio with carrier).
std::string solution_csv_header(bool carrier = false);
/// One CSV line (no newline) of a row.
std::string solution_csv_line(const SolutionRow& row);
/// Write rows as CSV to `path` atomically.
Expected<void> write_solution_csv(const std::string& path, const std::vector<SolutionRow>& rows);
/// Write rows in the RTKLIB solution format (GPST yyyy/mm/dd hh:mm:ss.sss, lat/lon deg, ellipsoidal h,
/// Q, ns, sdn/sde/sdu, sdne/sdeu/sdun, age, ratio) to `path` atomically; `comment` lines go into the header.
Expected<void> write_solution_pos(const std::string& path, const std::vector<SolutionRow>& rows,
                                  const std::vector<std::string>& comment);

/// GeoJSON (RFC 7946: WGS84 lon/lat/h in that order, no crs member) FeatureCollection: the track as one LineString
/// Feature, then one Point Feature per row with its time (gps_week, gps_tow_s, utc ISO 8601) and σ (sd_n_m, sd_e_m,
/// sd_d_m, the 1σ horizontal ellipse: semi-axes sigma_major_m / sigma_minor_m, orientation_deg clockwise from north),
/// n_sats_used, zupt. Written atomically; opens in QGIS as is.
Expected<void> write_solution_geojson(const std::string& path, const std::vector<SolutionRow>& rows,
                                      const std::string& title);
/// KML 2.2: a Document with the track as a LineString Placemark and one Point Placemark per row with its UTC
/// TimeStamp (Google Earth's time slider) and the same σ values as ExtendedData. Written atomically.
Expected<void> write_solution_kml(const std::string& path, const std::vector<SolutionRow>& rows, const std::string& title);

}  // namespace pednav::io
