// SPDX-License-Identifier: BSD-2-Clause
// YAML section reader: GNSS files (top level) and the `gnss:` options.
#include "io/config.hpp"
#include "io/yaml_schema.hpp"

namespace pednav::io {

void read_gnss_section(YamlMap& top, GnssConfig& out) {
  top.path("rover_obs", out.rover_obs);
  top.path("base_obs", out.base_obs);
  top.paths("nav", out.nav);
  if (top.has("base_position_ecef_m")) {
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    top.vector3("base_position_ecef_m", b);
    if (b.norm() < 6.0e6 || b.norm() > 6.5e6) {
      top.problem("base_position_ecef_m", "is not an ECEF position near the Earth's surface (|p| must be 6000-6500 km)");
    } else {
      out.base_position_ecef_m = b;
    }
  }
  YamlMap g = top.map("gnss");
  g.strings("systems", out.systems);
  for (const auto& s : out.systems) {
    if (s != "G" && s != "R" && s != "E" && s != "C" && s != "J") {
      g.problem("systems", "unknown system '" + s + "' (expected G, R, E, C or J)");
    }
  }
  double mask_deg = out.elevation_mask_rad * 180.0 / 3.14159265358979323846;
  g.number("elevation_mask_deg", mask_deg, false, 0.0, 90.0);
  out.elevation_mask_rad = mask_deg * 3.14159265358979323846 / 180.0;
  g.number("epoch_match_tolerance_s", out.epoch_match_tolerance_s, false, 0.0, 10.0);
  g.number("max_base_age_s", out.max_base_age_s, false, 0.0, 3600.0);
  g.number("min_cn0_dbhz", out.min_cn0_dbhz, false, 0.0, 70.0);
  g.boolean("use_doppler", out.use_doppler);
  g.choice("base_propagation", out.base_propagation, {"ephemeris", "doppler"});
  g.number("code_sigma_zenith_m", out.code_sigma_zenith_m, false, 0.001, 100.0);
  g.number("doppler_sigma_zenith_mps", out.doppler_sigma_zenith_mps, false, 0.0001, 10.0);
  g.number("cn0_ref_dbhz", out.cn0_ref_dbhz, false, 10.0, 70.0);
  g.number("glonass_code_factor", out.glonass_code_factor, false, 0.1, 100.0);
  g.number("elevation_weight", out.elevation_weight, false, 0.0, 1.0);
  g.number("code_squaring_loss", out.code_squaring_loss, false, 0.0, 10.0);
  g.number("code_smoothing_s", out.code_smoothing_s, false, 0.0, 3600.0);
  g.choice("carrier", out.carrier, {"auto", "on", "off"});
  g.number("carrier_sigma_zenith_m", out.carrier_sigma_zenith_m, false, 0.0001, 1.0);
  g.number("carrier_base_age_sigma_mps", out.carrier_base_age_sigma_mps, false, 0.0, 1.0);
  g.number("rtk_accel_sigma_horizontal_mps2", out.rtk_accel_sigma_horizontal_mps2, false, 0.001, 100.0);
  g.number("rtk_accel_sigma_vertical_mps2", out.rtk_accel_sigma_vertical_mps2, false, 0.001, 100.0);
  YamlMap a = g.map("ambiguity");
  auto& o = out.ambiguity;
  a.number("ratio_threshold", o.ratio_threshold, false, 1.0, 1000.0);
  a.number("tc_ratio_threshold", o.tc_ratio_threshold, false, 1.0, 1000.0);
  a.number("min_success_rate", o.min_success_rate, false, 0.0, 1.0);
  a.number("elevation_mask_deg", o.elevation_mask_deg, false, 0.0, 90.0);
  a.boolean("partial", o.partial);
  a.integer("min_ambiguities", o.min_ambiguities, false, 1, 100);
  a.integer("min_lock_epochs", o.min_lock_epochs, false, 0, 100000);
  a.boolean("hold", o.hold);
  a.integer("hold_min_epochs", o.hold_min_epochs, false, 1, 100000);
  a.number("hold_sigma_cycles", o.hold_sigma_cycles, false, 0.0001, 1.0);
  a.number("validation_w", o.validation_w, false, 1.0, 100.0);
  a.boolean("glonass", o.glonass);
  a.choice("glonass_ifb", o.glonass_ifb, {"search", "off"});
  a.finish();
}

}  // namespace pednav::io
