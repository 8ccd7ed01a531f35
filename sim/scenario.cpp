// SPDX-License-Identifier: BSD-2-Clause
// Scenario validation: every problem at once, named by the YAML key it comes from (docs/configuration.md
// "Scenario files").
#include "sim/scenario.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace pednav::sim {
namespace {
std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}
}  // namespace

std::vector<std::string> Scenario::problems() const {
  std::vector<std::string> p;
  auto range = [&](double v, double lo, double hi, const char* key) {
    if (!(v >= lo && v <= hi)) p.push_back(std::string(key) + " = " + num(v) + " must be in [" + num(lo) + ", " + num(hi) + "]");
  };
  if (track.empty() && waypoints.size() < 2) p.push_back("route.waypoints: at least 2 waypoints are needed");
  if (start.ns() % kNsPerS != 0) p.push_back("start: must be on an integer GPS second");
  range(static_start_s, 0.0, 86400.0, "route.static_start_s");
  range(static_end_s, 0.0, 86400.0, "route.static_end_s");
  range(gait.speed_mps, 0.1, 5.0, "gait.speed_mps");
  range(gait.cycle_s, 0.5, 3.0, "gait.cycle_s");
  range(gait.stance_fraction, 0.1, 0.8, "gait.stance_fraction");
  range(gait.cycle_sd_fraction, 0.0, 0.2, "gait.cycle_sd_fraction");
  range(gait.stride_sd_fraction, 0.0, 0.3, "gait.stride_sd_fraction");
  range(gait.clearance_m, 0.0, 0.5, "gait.clearance_m");
  range(gait.pitch_rate_peak_radps, 0.0, 15.0, "gait.pitch_rate_peak_radps");
  range(imu.rate_hz, 20.0, 2000.0, "imu.rate_hz");
  range(truth_rate_hz, 0.1, imu.rate_hz, "output.truth_rate_hz");
  const double ratio = imu.rate_hz / truth_rate_hz;
  if (std::abs(ratio - std::round(ratio)) > 1e-9) p.push_back("output.truth_rate_hz must divide imu.rate_hz");
  for (const auto& s : imu.spec.problems()) p.push_back("imu.spec: " + s);
  if (imu.carry != "foot" && imu.carry != "hand") p.push_back("imu.carry: expected foot or hand, got '" + imu.carry + "'");
  if (imu.carry == "hand" && !track.empty()) p.push_back("imu.carry: hand needs a route (not the along-a-track mode)");
  range(gnss.rate_hz, 0.1, 20.0, "gnss.rate_hz");
  range(gnss.satellites, 24, 32, "gnss.satellites");
  range(gnss.tracking_threshold_dbhz, 0.0, 60.0, "gnss.tracking_threshold_dbhz");
  if (gnss.acquisition_threshold_dbhz < gnss.tracking_threshold_dbhz)
    p.push_back("gnss.acquisition_threshold_dbhz must be >= gnss.tracking_threshold_dbhz");
  range(gnss.correlator_spacing_chips, 0.05, 1.5, "gnss.correlator_spacing_chips");
  range(gnss.dll_bandwidth_hz, 0.01, 10.0, "gnss.dll_bandwidth_hz");
  range(gnss.integration_time_s, 0.001, 1.0, "gnss.integration_time_s");
  range(gnss.multipath_tau_s, 0.01, 1e5, "gnss.multipath_tau_s");
  range(gnss.atmosphere_tau_s, 0.01, 1e6, "gnss.atmosphere_tau_s");
  range(gnss.blunder_rate, 0.0, 0.5, "gnss.blunder_rate");
  if (gnss.blunder_max_m < gnss.blunder_min_m) p.push_back("gnss.blunder_max_m must be >= gnss.blunder_min_m");
  if (gnss.blunder_max_s < gnss.blunder_min_s) p.push_back("gnss.blunder_max_s must be >= gnss.blunder_min_s");
  range(gnss.atmosphere_sd_iono_fraction, 0.0, 1.0, "gnss.atmosphere_sd_iono_fraction");
  range(gnss.carrier_tracking_threshold_dbhz, 0.0, 60.0, "gnss.carrier_tracking_threshold_dbhz");
  if (gnss.carrier_acquisition_threshold_dbhz < gnss.carrier_tracking_threshold_dbhz)
    p.push_back("gnss.carrier_acquisition_threshold_dbhz must be >= gnss.carrier_tracking_threshold_dbhz");
  range(gnss.pll_bandwidth_hz, 0.0, 50.0, "gnss.pll_bandwidth_hz");
  range(gnss.pll_integration_time_s, 0.001, 0.1, "gnss.pll_integration_time_s");
  range(gnss.carrier_multipath_sigma_m, 0.0, 0.1, "gnss.carrier_multipath_sigma_m");
  range(gnss.carrier_multipath_tau_s, 0.01, 1e5, "gnss.carrier_multipath_tau_s");
  range(gnss.carrier_ambiguity_max_cycles, 0, 10000000, "gnss.carrier_ambiguity_max_cycles");
  range(gnss.carrier_slip_rate_per_s, 0.0, 10.0, "gnss.carrier_slip_rate_per_s");
  range(gnss.carrier_slip_decade_db, 0.1, 60.0, "gnss.carrier_slip_decade_db");
  range(gnss.carrier_slip_max_cycles, 1, 1000000, "gnss.carrier_slip_max_cycles");
  range(gnss.carrier_slip_flagged_fraction, 0.0, 1.0, "gnss.carrier_slip_flagged_fraction");
  range(gnss.carrier_half_cycle_probability, 0.0, 1.0, "gnss.carrier_half_cycle_probability");
  range(gnss.carrier_half_cycle_s, 0.001, 3600.0, "gnss.carrier_half_cycle_s");
  for (size_t i = 0; i < gnss.attenuation.size(); ++i) {
    const auto& s = gnss.attenuation[i];
    const std::string k = "gnss.attenuation[" + std::to_string(i) + "]";
    if (!(s.to_m > s.from_m)) p.push_back(k + ": to_m must be > from_m");
    if (s.type != "open" && s.type != "foliage" && s.type != "indoor") p.push_back(k + ".type must be open, foliage or indoor");
    if (s.max_db < s.min_db) p.push_back(k + ": max_db must be >= min_db");
    if (!(s.tau_s > 0.0)) p.push_back(k + ".tau_s must be > 0");
  }
  return p;
}

}  // namespace pednav::sim
