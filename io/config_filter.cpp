// SPDX-License-Identifier: BSD-2-Clause
// YAML section reader: filter options (mechanization rate, ZUPT, fault rejection, smoother).
#include "core/geodesy.hpp"
#include "fusion/engine.hpp"
#include "io/config.hpp"
#include "io/yaml_schema.hpp"

namespace pednav::io {

void read_filter_section(YamlMap& top, RunConfig& out) {
  top.number("mechanization_rate_hz", out.mechanization_rate_hz, false, 1e-3, 2000.0);
  {
    YamlMap z = top.map("zupt");
    z.choice("detector", out.zupt.detector, {"mv", "shoe", "are", "mag", "hmm", "labels"});
    z.choice("form", out.zupt.form, {"D", "F"});
    ZuptConfig& c = out.zupt;
    z.number("mv_window_s", c.mv_window_s, false, 1e-3, 5.0);
    z.number("mv_threshold_mps2", c.mv_threshold_mps2, false, 1e-6, 100.0);
    double g = c.mv_gyro_threshold_radps * kRadToDeg;
    z.number("mv_gyro_threshold_deg_per_s", g, false, 0.0, 5000.0);
    c.mv_gyro_threshold_radps = g * kDegToRad;
    z.number("min_time_since_step_s", c.min_time_since_step_s, false, 0.0, 5.0);
    z.number("shoe_window_s", c.shoe_window_s, false, 1e-3, 5.0);
    z.number("shoe_sigma_accel_mps2", c.shoe_sigma_accel_mps2, false, 1e-6, 100.0);
    double sg = c.shoe_sigma_gyro_radps * kRadToDeg;
    z.number("shoe_sigma_gyro_deg_per_s", sg, false, 1e-6, 1000.0);
    c.shoe_sigma_gyro_radps = sg * kDegToRad;
    if (z.has("shoe_threshold") && z.raw("shoe_threshold").IsScalar() && z.raw("shoe_threshold").Scalar() == "auto") {
      c.shoe_threshold_auto = true;
    } else if (z.has("shoe_threshold")) {
      z.number("shoe_threshold", c.shoe_threshold, false, 1e-9, 1e12);
    } else if (out.imu.spec_auto && out.zupt.detector == "shoe") {
      // A self-calibrating IMU without a threshold takes the log's own (docs/zupt.md §5): the default.
      c.shoe_threshold_auto = true;
      c.shoe_threshold_defaulted = true;
    }
    z.number("shoe_threshold_motion", c.shoe_threshold_motion, false, 0.0, 1e6);
    if (z.has("shoe_threshold_motion") && !c.shoe_threshold_auto) {
      z.problem("shoe_threshold_motion", "only used with shoe_threshold: auto");
    }
    z.number("shoe_threshold_two_class_cap", c.shoe_threshold_two_class_cap, false, 0.0, 1e12);
    if (z.has("shoe_threshold_two_class_cap") && !c.shoe_threshold_auto) {
      z.problem("shoe_threshold_two_class_cap", "only used with shoe_threshold: auto");
    }
    z.number("min_stance_s", c.min_stance_s, false, 0.0, 5.0);
    read_zupt_hmm_keys(z, c);
    z.number("sigma_mps", c.sigma_mps, false, 1e-6, 10.0);
    c.edge_s_given = z.has("edge_s");
    z.number("edge_s", c.edge_s, false, 0.0, 1.0);
    z.boolean("zaru", c.zaru);
    z.boolean("updates", c.updates);
    c.zaru_sigma_given = z.has("zaru_sigma_deg_per_s");
    double zs = c.zaru_sigma_radps * kRadToDeg;
    z.number("zaru_sigma_deg_per_s", zs, false, 1e-9, 100.0);
    c.zaru_sigma_radps = zs * kDegToRad;
    c.zaru_gate_given = z.has("zaru_gate_probability");
    z.number("zaru_gate_probability", c.zaru_gate_probability, false, 0.0, 0.999999);
    if (c.zaru_gate_probability > 0.0 && c.zaru_gate_probability <= 0.5)
      z.problem("zaru_gate_probability", "must be 0 (no gate) or in (0.5, 1)");
  }
  {
    YamlMap v = top.map("step_velocity");
    fusion::StepVelocityOptions& sv = out.step_velocity;
    v.boolean("enabled", sv.enabled);
    v.number("leg_length_m", sv.leg_length_m, false, 0.05, 3.0);
    v.number("sigma_along_mps", sv.sigma_along_mps, false, 1e-4, 10.0);
    v.number("sigma_cross_mps", sv.sigma_cross_mps, false, 1e-4, 10.0);
    v.number("sigma_vertical_mps", sv.sigma_vertical_mps, false, 1e-4, 10.0);
    v.number("min_step_s", sv.min_step_s, false, 0.05, 10.0);
    v.number("max_step_s", sv.max_step_s, false, 0.1, 60.0);
    v.number("min_rise_m", sv.min_rise_m, false, 0.0, 1.0);
    if (sv.max_step_s <= sv.min_step_s) v.problem("max_step_s", "must be > min_step_s");
  }
  {
    YamlMap i = top.map("initial");
    InitialConfig& c = out.initial;
    if (i.has("yaw_deg")) {
      double y = 0.0;
      i.number("yaw_deg", y, false, -360.0, 360.0);
      c.yaw_rad = y * kDegToRad;
    }
    std::string heading = "auto";
    i.choice("heading", heading, {"auto", "magnetometer"});
    c.heading_from_magnetometer = heading == "magnetometer";
    if (c.heading_from_magnetometer && c.yaw_rad) {
      i.problem("heading", "magnetometer and yaw_deg both set the initial heading: keep one");
    }
    double decl_deg = c.declination_rad * kRadToDeg;
    i.number("declination_deg", decl_deg, false, -180.0, 180.0);
    c.declination_rad = decl_deg * kDegToRad;
    if (i.has("declination_deg") && !c.heading_from_magnetometer) {
      i.problem("declination_deg", "only used with heading: magnetometer");
    }
    if (i.has("position_ecef_m")) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      i.vector3("position_ecef_m", p);
      c.position_e = p;
    }
    if (i.has("lat_deg") || i.has("lon_deg") || i.has("h_m")) {
      Geodetic g0;
      double lat = 0, lon = 0, h = 0;
      i.number("lat_deg", lat, true, -90.0, 90.0);
      i.number("lon_deg", lon, true, -180.0, 360.0);
      i.number("h_m", h, true, -1000.0, 100000.0);
      g0 = {lat * kDegToRad, lon * kDegToRad, h};
      c.position_e = ecef_from_geodetic(g0);
    }
    i.number("heading_init_distance_m", c.heading_init_distance_m, false, 5.0, 10000.0);
    i.number("sigma_position_m", c.sigma_position_m, false, 1e-4, 1e5);
    i.number("sigma_velocity_mps", c.sigma_velocity_mps, false, 1e-5, 100.0);
    double t = c.sigma_tilt_rad * kRadToDeg, y = c.sigma_yaw_rad * kRadToDeg;
    i.number("sigma_tilt_deg", t, false, 1e-4, 90.0);
    i.number("sigma_yaw_deg", y, false, 1e-4, 180.0);
    c.sigma_tilt_rad = t * kDegToRad;
    c.sigma_yaw_rad = y * kDegToRad;
  }
  {
    YamlMap a = top.map("antenna");
    AntennaConfig& c = out.antenna;
    a.vector3("lever_arm_ned_m", c.lever_arm_ned_m);
    a.vector3("lever_arm_heading_m", c.lever_arm_heading_m);
    a.number("sigma_horizontal_m", c.sigma_horizontal_m, false, 0.0, 100.0);
    a.number("sigma_vertical_m", c.sigma_vertical_m, false, 0.0, 100.0);
    a.number("velocity_sigma_horizontal_mps", c.velocity_sigma_horizontal_mps, false, 0.0, 100.0);
    a.number("velocity_sigma_vertical_mps", c.velocity_sigma_vertical_mps, false, 0.0, 100.0);
    a.choice("velocity_model", c.velocity_model, {"stride_average", "foot"});
    a.number("stride_velocity_sigma_horizontal_mps", c.stride_velocity_sigma_horizontal_mps, false, 1e-3, 100.0);
    a.number("stride_velocity_sigma_vertical_mps", c.stride_velocity_sigma_vertical_mps, false, 1e-3, 100.0);
    a.number("stance_sigma_horizontal_m", c.stance_sigma_horizontal_m, false, 1e-3, 100.0);
    a.number("stance_sigma_vertical_m", c.stance_sigma_vertical_m, false, 1e-3, 100.0);
  }
  {
    YamlMap k = top.map("clock");
    k.number("psd_m2_per_s", out.clock.psd_m2_per_s, false, 0.0, 1e12);
    k.number("drift_psd_m2_per_s3", out.clock.drift_psd_m2_per_s3, false, 0.0, 1e12);
    k.number("jump_threshold_m", out.clock.jump_threshold_m, false, 1.0, 1e9);
  }
  {
    YamlMap f = top.map("fault_rejection");
    f.number("probability", out.fault_rejection_probability, false, 0.5, 1.0 - 1e-12);
    f.integer("window_epochs", out.fault_rejection_window_epochs, false, 0, fusion::kMaxFaultWindowEpochs);
  }
  {
    YamlMap s = top.map("smoother");
    s.boolean("enabled", out.smoother_enabled);
  }
  {
    YamlMap m = top.map("multipath");
    MultipathConfig& c = out.multipath;
    m.boolean("states", c.states);
    m.number("sigma_m", c.sigma_m, false, 1e-3, 100.0);
    m.number("tau_s", c.tau_s, false, 0.1, 1e5);
    m.number("cn0_ref_dbhz", c.cn0_ref_dbhz, false, 0.0, 80.0);
    m.integer("slots", c.slots, false, 1, 20);
    m.number("reset_gap_s", c.reset_gap_s, false, 0.0, 1e5);
  }
  {
    YamlMap s = top.map("scale_factors");
    if (s.has("states")) {
      std::string v;
      s.choice("states", v, {"auto", "true", "false"});
      if (v == "true") out.scale_factors.states = true;
      if (v == "false") out.scale_factors.states = false;
    }
    s.boolean("gyro", out.scale_factors.gyro);
    s.boolean("bias_compensation", out.scale_factors.bias_compensation);
  }
  {
    YamlMap b = top.map("bias");
    b.choice("model", out.bias.model, {"auto", "gauss_markov", "random_walk"});
  }
  {
    YamlMap s = top.map("saturation");
    s.boolean("repair", out.saturation.repair);
  }
}

}  // namespace pednav::io
