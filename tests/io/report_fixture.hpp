// SPDX-License-Identifier: BSD-2-Clause
// A small synthetic run folder for the report tests: a 1 Hz walk east at 1 m/s with a known error, forward and
// smoothed solutions (pednav CSV), a reference, evaluation files and one outage study subfolder.
#pragma once

#include <filesystem>
#include <fmt/format.h>

#include <fstream>
#include <string>

#include "core/geodesy.hpp"
#include "io/solution_writer.hpp"

namespace pednav::test {

/// Plots report.html must hold for this folder: trajectory, horizontal error, CDF, north and east +-3 sigma,
/// satellites, ZUPT timeline, outage RMS.
inline constexpr int kReportFixturePlots = 8;

inline void write_report_fixture(const std::string& dir) {
  namespace fs = std::filesystem;
  fs::create_directories(dir + "/outage_keep3");
  const Eigen::Vector3d p0 = ecef_from_geodetic({51.08 * kDegToRad, -114.13 * kDegToRad, 1050.0});
  const GpsTime t0 = GpsTime::from_week_tow(2300, 225000.0);
  std::ofstream ref(dir + "/reference.csv");
  ref << "gps_week,gps_tow_s,x_m,y_m,z_m\n";
  std::vector<io::SolutionRow> fwd, smo;
  for (int i = 0; i < 300; ++i) {
    const GpsTime t = t0.plus_s(i);
    const Eigen::Vector3d truth = ecef_from_ned(Eigen::Vector3d(0.0, 1.0 * i, 0.0), p0);
    ref << fmt::format("{},{:.3f},{:.4f},{:.4f},{:.4f}\n", t.week(), t.tow_s(), truth.x(), truth.y(), truth.z());
    io::SolutionRow r;
    r.time = t;
    r.p_e = ecef_from_ned(Eigen::Vector3d(0.5 * std::sin(0.05 * i), 1.0 * i, 0.2), p0);
    r.v_n = Eigen::Vector3d(0, 1, 0);
    r.rpy_deg = Eigen::Vector3d(0, 0, 90);
    r.cov_p_n = Eigen::Vector3d(0.09, 0.09, 0.25).asDiagonal();
    r.sd_yaw_deg = 1.0;
    r.n_sats_used = 7 - (i / 100);
    r.n_sats_rejected = i % 50 == 0 ? 1 : 0;
    r.zupt = i % 2 == 0;
    fwd.push_back(r);
    r.p_e = ecef_from_ned(Eigen::Vector3d(0.2 * std::sin(0.05 * i), 1.0 * i, 0.1), p0);
    smo.push_back(r);
  }
  ref.close();
  (void)io::write_solution_csv(dir + "/solution.csv", fwd);
  (void)io::write_solution_csv(dir + "/smoothed.csv", smo);
  std::ofstream(dir + "/config.resolved.yaml") << "mode: tc\nreference:\n  file: " << dir << "/reference.csv\n  format: csv\n";
  // A run summary with the health keys pednav run writes and the long floats it holds (rounded by the report).
  std::ofstream(dir + "/summary.json")
      << "{\"mode\": \"tc\", \"output_epochs\": 300, \"initial_yaw_deg\": 92.86770608856047, "
         "\"initial_gyro_bias_deg_per_h\": [2424.9135795483744, 271.8266973372757, -0.000012345678], "
         "\"zupt\": {\"updates\": 150, \"zaru_updates\": 140, \"zaru_rejected_by_gate\": 0, \"short_stance_interval_ends\": 3}, "
         "\"gnss\": {\"epochs_read\": 300, \"epochs_skipped_no_base\": 2, \"epochs_outside_imu_span\": 0, "
         "\"code\": {\"below_elevation_mask\": 30, \"innovation_fault\": 6, \"persistent_fault\": 1, \"used\": 1763}, "
         "\"doppler\": {\"innovation_fault\": 0, \"used\": 1800}}, "
         "\"warnings\": [{\"code\": \"gyro_bias\", \"message\": \"gyro bias estimate 958.0 °/h is beyond 3 σ of the spec "
         "(144.2 °/h)\", \"value\": 958.0, \"limit\": 432.6, \"hint\": \"try imu.spec: auto\"}], "
         "\"health\": {\"healthy\": true, \"reinitializations\": 1, "
         "\"events\": [\"re-initialized at 225120.0 s: speed 12.3 m/s\"]}, "
         "\"accounting\": {\"imu_samples\": {\"read\": 30000, \"used\": 29990, \"rejected\": {\"nan\": 4}, "
         "\"skipped\": {\"duplicate_time\": 6}}, \"gnss_measurements\": {\"read\": 1800}}, "
         "\"wall_s\": 1.478328488}\n";
  std::ofstream(dir + "/evaluation.json")
      << "{\"horizontal_rms_m\": 0.35, \"horizontal_max_m\": 0.5, \"availability_pct\": 100, "
         "\"bins_pct\": {\"lt5\": 100, \"5to10\": 0, \"10to20\": 0, \"ge20\": 0}}\n";
  std::ofstream(dir + "/evaluation_smoothed.json")
      << "{\"horizontal_rms_m\": 0.14, \"horizontal_max_m\": 0.2, \"availability_pct\": 100, "
         "\"bins_pct\": {\"lt5\": 100, \"5to10\": 0, \"10to20\": 0, \"ge20\": 0}}\n";
  std::ofstream rms(dir + "/outage_keep3/rms_vs_time.csv");
  rms << "t_since_outage_s,rms_horizontal_m,n_windows,rms_horizontal_smoothed_m,n_windows_smoothed\n";
  for (int t = 0; t <= 100; ++t) rms << fmt::format("{},{:.3f},5,{:.3f},5\n", t, 0.01 * t, 0.005 * t);
  rms.close();
  std::ofstream(dir + "/outage_keep3/outages.csv")
      << "window,start_gps_week,start_gps_tow_s,duration_s,keep_sats,sats_left_min,sats_left_mean,sats_left_max,"
         "gnss_epochs_emptied,max_error_m,end_error_m,max_error_smoothed_m,end_error_smoothed_m\n"
         "1,2300,225100.000,100.000,3,3,3.00,3,0,1.200,1.000,0.600,0.500\n";
  std::ofstream(dir + "/outage_keep3/summary.json")
      << "{\"windows\": 1, \"duration_s\": 100, \"keep_sats\": 3, \"max_error_m\": 1.2, \"rms_at_end_m\": 1.0, "
         "\"against\": \"reference\", \"smoothed\": {\"max_error_m\": 0.6, \"rms_at_end_m\": 0.5}}\n";
}

}  // namespace pednav::test
