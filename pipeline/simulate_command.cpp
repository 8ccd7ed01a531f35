// SPDX-License-Identifier: BSD-2-Clause
// `pednav simulate` outputs (docs/sim.md §7): the simulator's data formatted and written atomically.
#include "pipeline/simulate_command.hpp"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "io/atomic_file.hpp"
#include "io/rinex_writer.hpp"
#include "sim/gnss_sim.hpp"

namespace pednav::pipeline {

using namespace pednav::io;  // the readers, writers and configuration this use case drives
namespace {

long truth_step(const sim::Simulation& s) {
  return std::max(1L, std::lround(s.scenario.imu.rate_hz / s.scenario.truth_rate_hz));
}

std::string yaml_path(const std::string& p) {
  std::string q = "'";
  for (char c : p) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

}  // namespace

std::string format_truth_csv(const sim::Simulation& s) {
  std::string out =
      "gps_week,gps_tow_s,lat_deg,lon_deg,h_m,x_m,y_m,z_m,vn_mps,ve_mps,vd_mps,roll_deg,pitch_deg,yaw_deg,"
      "ant_x_m,ant_y_m,ant_z_m,stance,route_m\n";
  const long step = truth_step(s);
  out.reserve(static_cast<size_t>(s.truth.nav.size() / static_cast<size_t>(step) + 1) * 230);
  fmt::memory_buffer buf;
  for (size_t k = 0; k < s.truth.nav.size(); k += static_cast<size_t>(step)) {
    const ins::NavState& x = s.truth.nav[k];
    const Geodetic llh = geodetic_from_ecef(x.p_eb_e);
    const Eigen::Matrix3d R_n_e = R_e_n(llh.lat, llh.lon).transpose();
    const Eigen::Vector3d v_n = R_n_e * x.v_eb_e;
    const Eigen::Vector3d rpy = euler_from_R_n_b(R_n_e * x.R_e_b()) * kRadToDeg;
    const Eigen::Vector3d& a = s.antenna[k].p_e;
    buf.clear();
    fmt::format_to(std::back_inserter(buf),
                   "{},{:.9f},{:.10f},{:.10f},{:.5f},{:.5f},{:.5f},{:.5f},{:.7f},{:.7f},{:.7f},{:.9f},{:.9f},{:.9f},"
                   "{:.4f},{:.4f},{:.4f},{},{:.3f}\n",
                   x.t.week(), x.t.tow_s(), llh.lat * kRadToDeg, llh.lon * kRadToDeg, llh.h_m, x.p_eb_e.x(), x.p_eb_e.y(),
                   x.p_eb_e.z(), v_n.x(), v_n.y(), v_n.z(), rpy.x(), rpy.y(), rpy.z(), a.x(), a.y(), a.z(),
                   static_cast<int>(s.truth.stance[k]), s.antenna[k].route_m);
    out.append(buf.data(), buf.size());
  }
  return out;
}

std::string format_imu_csv(const sim::Simulation& s) {
  std::string out = "gps_week,gps_tow_s,gyro_x_radps,gyro_y_radps,gyro_z_radps,accel_x_mps2,accel_y_mps2,accel_z_mps2\n";
  out.reserve(s.imu.size() * 110 + 100);
  fmt::memory_buffer buf;
  for (const auto& m : s.imu) {
    buf.clear();
    fmt::format_to(std::back_inserter(buf), "{},{:.9f},{:.10f},{:.10f},{:.10f},{:.9f},{:.9f},{:.9f}\n", m.t.week(),
                   m.t.tow_s(), m.omega_ib_b.x(), m.omega_ib_b.y(), m.omega_ib_b.z(), m.f_ib_b.x(), m.f_ib_b.y(),
                   m.f_ib_b.z());
    out.append(buf.data(), buf.size());
  }
  return out;
}

void apply_data_sheet(const sim::Scenario& sc, const DataSheetParts& parts, RunConfig& c) {
  if (parts.receiver_weights) {  // docs/consistency.md §3.8
    const gnss::WeightModel w = sim::receiver_weight_model(sc.gnss);
    c.gnss.cn0_ref_dbhz = w.cn0_ref_dbhz;
    c.gnss.code_sigma_zenith_m = w.code_sigma_zenith_m;
    c.gnss.doppler_sigma_zenith_mps = w.doppler_sigma_zenith_mps;
    c.gnss.elevation_weight = w.elevation_weight;
    c.gnss.code_squaring_loss = w.code_squaring_loss;
    if (sc.gnss.carrier_phase) c.gnss.carrier_sigma_zenith_m = sim::receiver_carrier_sigma_zenith_m(sc.gnss);
  }
  if (parts.lever_arm && sc.imu.carry == "hand") {  // the device's own antenna (docs/sim.md §9)
    c.antenna.lever_arm_ned_m.setZero();
    c.antenna.lever_arm_heading_m.setZero();
  } else if (parts.lever_arm) {  // docs/fusion.md §14: antenna height over the foot IMU, the foot beside the line
    c.antenna.lever_arm_ned_m = Eigen::Vector3d(0.0, 0.0, -(sc.gnss.antenna_height_m - sc.gait.imu_height_m));
    c.antenna.lever_arm_heading_m = Eigen::Vector3d(0.0, -sc.gait.foot_offset_m, 0.0);
  }
  if (parts.g_sensitivity) c.imu.spec.gyro_g_sensitivity = sc.imu.gyro_g_sensitivity_sigma;  // docs/error_state.md §5
  if (parts.multipath) {  // docs/consistency.md §3
    constexpr double kMinSigma_m = 1e-3;  // the run configuration's lower limit of multipath.sigma_m
    c.multipath.states = sc.gnss.multipath_sigma_m >= kMinSigma_m;
    if (c.multipath.states) c.multipath.sigma_m = sc.gnss.multipath_sigma_m;
    c.multipath.tau_s = sc.gnss.multipath_tau_s;
    c.multipath.cn0_ref_dbhz = sc.gnss.multipath_cn0_ref_dbhz;
  }
}

namespace {

// config.yaml (data_sheet == nullptr) or config_datasheet.yaml text.
std::string format_config(const sim::Simulation& s, const ScenarioFile& f, const DataSheetParts* data_sheet) {
  const sim::Scenario& sc = s.scenario;
  const bool any_gnss = s.has_gnss || f.real_gnss.has_value();
  std::string y = fmt::format("# Written by pednav simulate from {} (seed {}). Paths are relative to this file.\n",
                              f.source_file, sc.seed);
  RunConfig ds;  // the data-sheet values (only the parts named are read below)
  if (data_sheet) {
    apply_data_sheet(sc, *data_sheet, ds);
    y += "# The data-sheet configuration: the filter gets the simulated sensors' own models instead of pednav run's\n"
         "# generic defaults (pednav montecarlo --receiver-weights --scenario-lever-arm --g-sensitivity-states\n"
         "# --multipath-states, where they apply to this scenario; docs/sim.md §7, docs/consistency.md §3.8-3.11).\n";
    y += any_gnss ? "mode: tc\n" : "mode: ins\n";
  } else if (any_gnss) {
    y += "# mode tc: `pednav run` runs the tightly coupled filter; `pednav gnss` (GNSS epochs by least squares) and\n"
         "# `pednav outage` take this file as it is.\nmode: tc\n";
  } else {
    y += "mode: ins\n";
  }
  if (f.real_gnss) {
    const RealGnssFiles& r = *f.real_gnss;
    const auto abs = [](const std::string& p) { return std::filesystem::absolute(p).lexically_normal().string(); };
    y += "rover_obs: " + yaml_path(abs(r.rover_obs)) + "\n";
    if (!r.base_obs.empty()) y += "base_obs: " + yaml_path(abs(r.base_obs)) + "\n";
    y += "nav: [";
    for (size_t i = 0; i < r.nav.size(); ++i) y += (i ? ", " : "") + yaml_path(abs(r.nav[i]));
    y += "]\n";
    if (r.base_position_ecef_m) {
      const auto& b = *r.base_position_ecef_m;
      y += fmt::format("base_position_ecef_m: [{:.4f}, {:.4f}, {:.4f}]\n", b.x(), b.y(), b.z());
    }
  } else if (s.has_gnss) {
    const Eigen::Vector3d& b = s.gnss.p_base_e;
    y += "rover_obs: rover.obs\nbase_obs: base.obs\nnav: [nav.rnx]\n";
    y += fmt::format("base_position_ecef_m: [{:.4f}, {:.4f}, {:.4f}]\n", b.x(), b.y(), b.z());
    y += fmt::format("gnss:\n  elevation_mask_deg: {:g}\n", std::max(10.0, sc.gnss.elevation_mask_rad * kRadToDeg));
    if (data_sheet && data_sheet->receiver_weights) {
      // Shortest round-trip decimal ({}): the file loads to exactly the values pednav montecarlo uses.
      y += fmt::format(
          "  cn0_ref_dbhz: {}\n  code_sigma_zenith_m: {}\n  doppler_sigma_zenith_mps: {}\n  elevation_weight: {}\n"
          "  code_squaring_loss: {}\n",
          ds.gnss.cn0_ref_dbhz, ds.gnss.code_sigma_zenith_m, ds.gnss.doppler_sigma_zenith_mps,
          ds.gnss.elevation_weight, ds.gnss.code_squaring_loss);
      if (sc.gnss.carrier_phase) y += fmt::format("  carrier_sigma_zenith_m: {}\n", ds.gnss.carrier_sigma_zenith_m);
    }
  }
  y += "imu:\n  file: imu.csv\n";
  y += fmt::format(
      "  format:\n    delimiter: \",\"\n    header_lines: 1\n    time: {{base: gps_sow, column: 1, unit: s, gps_week: {}}}\n"
      "    gyro: {{columns: [2, 3, 4], unit: rad_per_s}}\n    accel: {{columns: [5, 6, 7], unit: mps2}}\n",
      s.imu.front().t.week());
  if (data_sheet && data_sheet->g_sensitivity) {
    // The scenario's whole spec (preset + its g-sensitivity σ), inline so that it reads back to the same values.
    ins::ImuSpec spec = sc.imu.spec;
    spec.gyro_g_sensitivity = sc.imu.gyro_g_sensitivity_sigma;
    y += "  spec: " + imu_spec_flow_yaml(spec, f.imu_spec_preset) + "\n";
  } else {
    y += "  spec: " + f.imu_spec_preset + "\n";
  }
  y += fmt::format("mechanization_rate_hz: {:g}\n", 20.0);
  if (!any_gnss) {  // mode ins needs the initial position and heading: the truth's
    const ins::NavState& x0 = s.truth.nav.front();
    const Geodetic llh = geodetic_from_ecef(x0.p_eb_e);
    const Eigen::Vector3d rpy = euler_from_R_n_b(R_e_n(llh.lat, llh.lon).transpose() * x0.R_e_b());
    y += fmt::format("initial:\n  lat_deg: {:.10f}\n  lon_deg: {:.10f}\n  h_m: {:.4f}\n  yaw_deg: {:.6f}\n",
                     llh.lat * kRadToDeg, llh.lon * kRadToDeg, llh.h_m, rpy.z() * kRadToDeg);
  }
  if (data_sheet && data_sheet->lever_arm) {
    const Eigen::Vector3d &a = ds.antenna.lever_arm_ned_m, &h = ds.antenna.lever_arm_heading_m;
    y += fmt::format("antenna:\n  lever_arm_ned_m: [{}, {}, {}]\n  lever_arm_heading_m: [{}, {}, {}]\n", a.x(), a.y(),
                     a.z(), h.x(), h.y(), h.z());
    if (sc.imu.carry == "hand") y += "  velocity_model: foot\n";
  } else if (any_gnss && sc.imu.carry == "hand") {
    // A hand-held device: the antenna is the device's own, so the Doppler rows predict the IMU's velocity.
    y += "antenna:\n  lever_arm_ned_m: [0, 0, 0]\n  velocity_model: foot\n";
  }
  if (data_sheet && data_sheet->multipath) {
    y += ds.multipath.states ? fmt::format("multipath:\n  states: true\n  sigma_m: {}\n  tau_s: {}\n  cn0_ref_dbhz: {}\n",
                                           ds.multipath.sigma_m, ds.multipath.tau_s, ds.multipath.cn0_ref_dbhz)
                             : std::string("multipath:\n  states: false\n");
  }
  if (f.real_gnss) {
    y += "reference:\n  file: " + yaml_path(std::filesystem::absolute(f.real_gnss->reference_file).lexically_normal().string()) +
         "\n  format: " + (f.real_gnss->reference_format.empty() ? "nmea" : f.real_gnss->reference_format) + "\n";
    if (f.real_gnss->reference_format == "nmea") y += "  nmea_qualities: [4]   # score against RTK-fixed epochs only\n";
  } else {
    y += "reference:\n  file: truth.csv\n  format: csv\n";
  }
  return y;
}

}  // namespace

std::string format_run_config(const sim::Simulation& s, const ScenarioFile& f) { return format_config(s, f, nullptr); }

std::string format_data_sheet_config(const sim::Simulation& s, const ScenarioFile& f) {
  DataSheetParts parts;
  parts.g_sensitivity = true;
  parts.lever_arm = s.has_gnss || f.real_gnss.has_value();
  parts.receiver_weights = parts.multipath = s.has_gnss && !f.real_gnss;
  return format_config(s, f, &parts);
}

Expected<SimulateSummary> run_simulate_command(const ScenarioFile& file, const std::string& out_dir) {
  const auto t0 = std::chrono::steady_clock::now();
  auto sim = sim::simulate(file.scenario);
  if (!sim) return make_error(file.source_file + ": " + sim.error().message);
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return make_error(out_dir + ": cannot create output folder: " + ec.message());
  const std::filesystem::path dir(out_dir);
  auto put = [&](const char* name, const std::string& text) { return write_file_atomic((dir / name).string(), text); };
  if (auto r = put("truth.csv", format_truth_csv(*sim)); !r) return r.error();
  if (auto r = put("imu.csv", format_imu_csv(*sim)); !r) return r.error();
  SimulateSummary sum;
  if (sim->has_gnss) {
    RinexObsHeader h;
    h.interval_s = 1.0 / sim->scenario.gnss.rate_hz;
    if (auto r = write_rinex_obs((dir / "rover.obs").string(), sim->gnss.rover, h); !r) return r.error();
    h.receiver_type = "PEDNAV SIM BASE";
    if (auto r = write_rinex_obs((dir / "base.obs").string(), sim->gnss.base, h); !r) return r.error();
    if (auto r = write_rinex_nav((dir / "nav.rnx").string(), sim->nav); !r) return r.error();
    std::string b = "gps_week,gps_tow_s,receiver,sat,error_m,event\n";
    for (const auto& x : sim->gnss.blunders)
      b += fmt::format("{},{:.3f},rover,{},{:.3f},{}\n", x.t.week(), x.t.tow_s(), x.sat.to_string(), x.error_m, x.id);
    if (auto r = put("blunders.csv", b); !r) return r.error();
    if (sim->scenario.gnss.carrier_phase) {  // carrier truth (docs/sim.md §8); no file without carrier phase
      std::string sl = "gps_week,gps_tow_s,receiver,sat,kind,cycles\n";
      for (const auto& x : sim->gnss.carrier_events)
        sl += fmt::format("{},{:.3f},{},{},{},{:.1f}\n", x.t.week(), x.t.tow_s(), x.rover ? "rover" : "base",
                          x.sat.to_string(), sim::carrier_event_name(x.kind), x.cycles);
      if (auto r = put("slips.csv", sl); !r) return r.error();
      sum.carrier_phase = true;
      sum.carrier_events = static_cast<int>(sim->gnss.carrier_events.size());
    }
    sum.rover_epochs = static_cast<int>(sim->gnss.rover.epochs.size());
    sum.base_epochs = static_cast<int>(sim->gnss.base.epochs.size());
    sum.blunder_events = sim->gnss.blunder_events;
  }
  if (auto r = put("config.yaml", format_run_config(*sim, file)); !r) return r.error();
  if (auto r = put("config_datasheet.yaml", format_data_sheet_config(*sim, file)); !r) return r.error();
  sum.duration_s = sim->plan.duration_s;
  sum.distance_m = sim->plan.distance_m;
  sum.strides = static_cast<int>(sim->plan.strides.size());
  sum.imu_samples = static_cast<long>(sim->imu.size());
  sum.truth_rows = static_cast<long>((sim->truth.nav.size() + static_cast<size_t>(truth_step(*sim)) - 1) /
                                     static_cast<size_t>(truth_step(*sim)));
  sum.saturated_samples = sim->imu_errors.saturated_samples;
  for (const auto& m : sim->truth.imu) sum.max_gyro_radps = std::max(sum.max_gyro_radps, m.omega_ib_b.norm());
  sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return sum;
}

}  // namespace pednav::pipeline
