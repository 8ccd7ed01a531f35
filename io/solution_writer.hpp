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
};

/// The DESIGN.md solution.csv header (+ hdop, pdop).
std::string solution_csv_header();
/// One CSV line (no newline) of a row.
std::string solution_csv_line(const SolutionRow& row);
/// Write rows as CSV to `path` atomically.
Expected<void> write_solution_csv(const std::string& path, const std::vector<SolutionRow>& rows);
/// Write rows in the RTKLIB solution format (GPST yyyy/mm/dd hh:mm:ss.sss, lat/lon deg, ellipsoidal h,
/// Q, ns, sdn/sde/sdu, sdne/sdeu/sdun, age, ratio) to `path` atomically; `comment` lines go into the header.
Expected<void> write_solution_pos(const std::string& path, const std::vector<SolutionRow>& rows,
                                  const std::vector<std::string>& comment);

}  // namespace pednav::io
