// SPDX-License-Identifier: BSD-2-Clause
// Helpers of the `pednav gnss` data tests (tests/pipeline/data_gnss_command.cpp: issue 3 and bad inputs;
// tests/pipeline/data_gnss_rtk.cpp: the kinematic RTK of issue 48): the Galway and Spirent references, gnss.csv
// reading and scoring, and a run from a YAML text into this process's temporary folder.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "gnss/types.hpp"
#include "io/config.hpp"
#include "pipeline/gnss_command.hpp"
#include "tests/support/data.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::pipeline::gnss_data {

using test::shared_data;

constexpr double kTimeMatch_s = 0.1;

// Horizontal RMS / p95 / max [m] of a `pednav gnss` run (figures measured: data_gnss_command.cpp).
struct Measured2d {
  double rms, p95, max;
};
// The Galway walk with its M8P base, GPS + GLONASS code (and Doppler) only, measured 2026-12-05: the figure the
// carrier rows of data_gnss_rtk.cpp are compared with.
constexpr Measured2d kGalwayGR{1.279, 2.272, 3.454};

inline const std::string kGalway = "gnss_ublox_m8p_walk_galway/";

struct Stats {
  int compared = 0;
  double rms = 0, p95 = 0, max = 0;
};

inline Stats stats_of(std::vector<double> e) {
  Stats s;
  s.compared = static_cast<int>(e.size());
  if (e.empty()) return s;
  std::sort(e.begin(), e.end());
  double sum = 0;
  for (double v : e) sum += v * v;
  s.rms = std::sqrt(sum / e.size());
  s.p95 = e[static_cast<size_t>(std::ceil(0.95 * e.size())) - 1];
  s.max = e.back();
  return s;
}

struct CsvRow {
  double tow_s;
  Eigen::Vector3d p_e, v_n;
  std::string status;  // solution_status (with carrier)
};

inline std::vector<CsvRow> read_gnss_csv(const std::string& path) {
  std::vector<CsvRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    CsvRow r;
    r.tow_s = std::stod(c[1]);
    r.p_e = Eigen::Vector3d(std::stod(c[5]), std::stod(c[6]), std::stod(c[7]));
    r.v_n = c[8].empty() ? Eigen::Vector3d::Constant(gnss::kNaN) : Eigen::Vector3d(std::stod(c[8]), std::stod(c[9]), std::stod(c[10]));
    if (c.size() > 23) r.status = c[23];
    rows.push_back(r);
  }
  return rows;
}

// RTK-fixed GGA epochs (quality 4) of the Galway rover: GPST time of day [s] -> ECEF [m] (h = alt + geoid sep).
inline std::map<long, Eigen::Vector3d> galway_truth() {
  std::map<long, Eigen::Vector3d> t;
  std::ifstream in(shared_data(kGalway + "reference_nmea/rover-20181004-1532.nmea"));
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("$GNGGA", 0) != 0) continue;
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    if (c.size() < 12 || c[6] != "4") continue;
    const double tod = std::stod(c[1].substr(0, 2)) * 3600 + std::stod(c[1].substr(2, 2)) * 60 + std::stod(c[1].substr(4));
    const double lat = (std::stod(c[2].substr(0, 2)) + std::stod(c[2].substr(2)) / 60) * (c[3] == "N" ? 1 : -1);
    const double lon = (std::stod(c[4].substr(0, 3)) + std::stod(c[4].substr(3)) / 60) * (c[5] == "E" ? 1 : -1);
    const double h = std::stod(c[9]) + std::stod(c[11]);
    t[std::lround(tod + 18.0)] = ecef_from_geodetic({lat * kDegToRad, lon * kDegToRad, h});  // UTC = GPST - 18 s
  }
  return t;
}

inline Stats galway_errors(const std::string& csv) {
  const auto truth = galway_truth();
  std::vector<double> e;
  for (const auto& r : read_gnss_csv(csv)) {
    const double tod = std::fmod(r.tow_s, 86400.0);
    auto it = truth.find(std::lround(tod));
    if (it == truth.end() || std::abs(tod - it->first) > kTimeMatch_s) continue;
    const Eigen::Vector3d enu = enu_from_ecef(r.p_e, it->second);
    e.push_back(std::hypot(enu.x(), enu.y()));
  }
  return stats_of(e);
}

inline std::string out_dir(const std::string& name) {
  return test::temp_dir_path("gnss_" + name).string();  // this process's own folder
}

inline Expected<GnssRunSummary> run(const std::string& yaml, const std::string& name) {
  auto cfg = io::parse_run_config(yaml, name + ".yaml", "/");
  if (!cfg) return cfg.error();
  return run_gnss_command(*cfg, out_dir(name));
}

inline std::string galway_yaml(const std::string& systems, const std::string& base_obs = "rinex/base-20181004-1452.obs",
                        const std::string& base_pos = "[3774085.6456, -601662.5769, 5089316.3970]",
                        const std::string& extra_nav = "") {
  return "mode: gnss\nrover_obs: " + shared_data(kGalway + "rinex/rover-20181004-1532.obs") +
         "\nbase_obs: " + shared_data(kGalway + base_obs) + "\nnav: [" +
         shared_data(kGalway + "rinex/base-20181004-1452.nav") + extra_nav + "]\nbase_position_ecef_m: " + base_pos +
         "\ngnss:\n  carrier: off\n  systems: " + systems + "\n";
}

// Spirent truth at 10 Hz: round(GpsToW · 10) -> ECEF (columns 3..6 of the PVA file in folder d).
inline std::map<long, Eigen::Vector3d> spirent_truth(const std::string& d) {
  std::map<long, Eigen::Vector3d> truth;
  std::ifstream in(d + "Rover-dynamic_PVA_Spirent.csv");
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<double> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(std::stod(cell));
    truth[std::lround(c[3] * 10)] = Eigen::Vector3d(c[4], c[5], c[6]);
  }
  return truth;
}

// The Spirent dynamic rover against its base (Klobuchar/Saastamoinen folder) in folder d, then `gnss_section`.
inline std::string spirent_yaml(const std::string& d, const std::string& gnss_section) {
  return "mode: gnss\nrover_obs: " + d + "iono-Klob_tropo-Saast/Rover-dynamic_MO_Spirent.obs\n" + "base_obs: " + d +
         "iono-Klob_tropo-Saast/Base-static_MO_Spirent.obs\nnav: [" + d + "RINEX_GN_Spirent.23N, " + d +
         "RINEX_EN_Spirent.23L]\n" + "base_position_ecef_m: [4157177.06580187, 671230.476590636, 4774767.03105544]\n" +
         gnss_section;
}

}  // namespace pednav::pipeline::gnss_data
