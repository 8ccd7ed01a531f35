// SPDX-License-Identifier: BSD-2-Clause
// Magnetometer heading initialization (initial.heading: magnetometer) on the four LORD 3DM-GX5-25 hallway logs
// (../shared/datasets/foot_lord_gcp_hallway): the committed lord_NN.yaml with the magnetometer instead of yaw_deg 0.
// Two references, neither of them a true north:
// - the device's own yaw (column 12 of the SensorConnect export: LORD's attitude filter, which also uses the
//   magnetometer, with its own hard/soft-iron calibration) at the first sample: the same quantity computed
//   independently;
// - the footprint track (GCP): every walk starts along the hallway (+x of the footprint frame, the floor tiles), so
//   the azimuth of the INS track's first leg (start → first output 5 m away) is the hallway's magnetic azimuth plus
//   the foot's walking direction; walks in the same hallway and direction must agree on it. Its spread over the four
//   logs is what the magnetometer heading is worth here (indoors, next to steel).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/geodesy.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "tests/support/data.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::pipeline {
namespace {

using namespace pednav::io;

double wrap_deg(double a) { return std::remainder(a, 360.0); }

// The device's yaw [deg] at the first data row of a SensorConnect export.
double device_yaw0_deg(const std::string& log) {
  std::ifstream in(log);
  std::string line;
  std::getline(in, line);
  std::getline(in, line);
  std::stringstream ss(line);
  std::string cell;
  double v = NAN;
  for (int c = 0; c <= 12 && std::getline(ss, cell, ','); ++c) {
    if (c == 12) v = std::stod(cell);
  }
  return v * kRadToDeg;
}

struct LogFigures {
  double yaw_mag_deg = NAN, yaw_device_deg = NAN, first_leg_azimuth_deg = NAN, field_ut = NAN, dip_deg = NAN;
};

LogFigures run_log(const std::string& n) {
  LogFigures f;
  auto cfg = load_run_config(test::source_path("datasets/foot/lord_" + n + ".yaml"));
  EXPECT_TRUE(cfg) << cfg.error().message;
  if (!cfg) return f;
  cfg->initial.yaw_rad.reset();
  cfg->initial.heading_from_magnetometer = true;
  cfg->initial.declination_rad = 0.0;  // the hallway's location is not documented: magnetic azimuths
  const auto out = test::temp_dir_path("data_lord_mag_" + n);
  std::filesystem::remove_all(out);
  auto sum = run_run_command(*cfg, out.string());
  EXPECT_TRUE(sum) << n << ": " << sum.error().message;
  if (!sum) return f;
  f.yaw_mag_deg = sum->initial_yaw_deg;
  f.field_ut = sum->magnetometer_field_norm;
  f.dip_deg = sum->magnetometer_dip_deg;
  f.yaw_device_deg = device_yaw0_deg(cfg->imu.file);
  // First leg of the INS track: from the first output to the first one 5 m away horizontally.
  std::ifstream in(out / "solution.csv");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> head;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) head.push_back(c);
  }
  const auto col = [&](const char* name) { return std::find(head.begin(), head.end(), name) - head.begin(); };
  const auto ix = col("x_m"), iy = col("y_m"), iz = col("z_m");
  EXPECT_LT(static_cast<size_t>(iz), head.size());
  std::optional<Eigen::Vector3d> p0;
  while (std::getline(in, line)) {
    std::vector<std::string> c;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) c.push_back(x);
    const Eigen::Vector3d p(std::stod(c[ix]), std::stod(c[iy]), std::stod(c[iz]));
    if (!p0) {
      p0 = p;
      continue;
    }
    const Eigen::Vector3d d_ned = ned_from_ecef(p, *p0);
    if (d_ned.head<2>().norm() >= 5.0) {
      f.first_leg_azimuth_deg = std::atan2(d_ned.y(), d_ned.x()) * kRadToDeg;
      break;
    }
  }
  return f;
}

TEST(DataLordMagnetometer, InitialHeadingAgainstTheDeviceYawAndTheHallwayFirstLeg) {
  PEDNAV_REQUIRE_DATA(test::shared_data("foot_lord_gcp_hallway/SensorConnectData_31.csv"));
  // Measured 2026-12-05 per log: (ours − device yaw, first-leg azimuth, dip) = #31 (−1.1°, 108.8°, 45.6°),
  // #34 (−1.2°, −44.1°, 9.6°), #35 (−2.5°, −49.9°, 14.2°), #38 (−1.1°, −16.2°, 47.9°); fields 43–61 µT.
  struct Expected {
    const char* n;
    double leg_deg, dip_deg;
  };
  std::vector<double> legs, device_diff;
  for (const Expected x : {Expected{"31", 108.8, 45.6}, Expected{"34", -44.1, 9.6}, Expected{"35", -49.9, 14.2},
                           Expected{"38", -16.2, 47.9}}) {
    const char* n = x.n;
    const LogFigures f = run_log(n);
    const double d = wrap_deg(f.yaw_mag_deg - f.yaw_device_deg);
    std::printf("[lord mag] #%s: yaw from the magnetometer %.1f deg, device yaw %.1f deg (difference %.1f deg); "
                "first-leg azimuth %.1f deg; field %.1f uT, dip %.1f deg\n",
                n, f.yaw_mag_deg, f.yaw_device_deg, d, f.first_leg_azimuth_deg, f.field_ut, f.dip_deg);
    ASSERT_TRUE(std::isfinite(f.first_leg_azimuth_deg)) << n;
    legs.push_back(f.first_leg_azimuth_deg);
    device_diff.push_back(d);
    // Deterministic runs: the figures to 0.5° (another libm), the field inside the Earth's range.
    EXPECT_NEAR(wrap_deg(f.first_leg_azimuth_deg - x.leg_deg), 0.0, 0.5) << n;
    EXPECT_NEAR(f.dip_deg, x.dip_deg, 0.5) << n;
    EXPECT_GT(f.field_ut, 22.0) << n;
    EXPECT_LT(f.field_ut, 67.0) << n;
  }
  double spread = 0.0;
  for (double a : legs) {
    for (double b : legs) spread = std::max(spread, std::abs(wrap_deg(a - b)));
  }
  double worst_device = 0.0;
  for (double d : device_diff) worst_device = std::max(worst_device, std::abs(d));
  std::printf("[lord mag] first-leg azimuth spread over the 4 logs %.1f deg; largest |ours - device| %.1f deg\n",
              spread, worst_device);
  // Ours agrees with the device's own magnetometer-aided yaw: measured worst 2.5°, bound × 1.25.
  EXPECT_LT(worst_device, 2.5 * 1.25);
  // The first legs do not agree (158.6° apart): the footprint frames are per walk (x = the first leg), so the walks
  // did not all start in one direction of one hallway, and a dip that changes from 9.6° to 47.9° between walks (the
  // Earth's dip does not change within a building) shows a field bent by the building. The footprints cannot check an absolute heading;
  // docs/results.md "Magnetometer heading".
  EXPECT_NEAR(spread, 158.6, 1.0);
}

}  // namespace
}  // namespace pednav::pipeline
