// SPDX-License-Identifier: BSD-2-Clause
// IMU spec presets. Sources and conversions: docs/ins.md §5 (which values are datasheet figures and which are
// assumptions is stated there, per value).
#include "ins/imu_spec.hpp"

#include "core/geodesy.hpp"

namespace pednav::ins {
namespace {

constexpr double kG0 = 9.80665;                                   // standard gravity [m/s^2] (mg, ug units)
constexpr double deg_per_sqrt_hr(double v) { return v * kDegToRad / 60.0; }  // -> rad/sqrt(s)
constexpr double deg_per_hr(double v) { return v * kDegToRad / 3600.0; }      // -> rad/s
constexpr double deg_per_s(double v) { return v * kDegToRad; }                // -> rad/s
constexpr double deg_per_s_sqrt_hz(double v) { return v * kDegToRad; }       // -> rad/sqrt(s)
constexpr double mps_per_sqrt_hr(double v) { return v / 60.0; }               // -> m/s/sqrt(s)
constexpr double milli_g(double v) { return v * 1e-3 * kG0; }                 // -> m/s^2
constexpr double micro_g_sqrt_hz(double v) { return v * 1e-6 * kG0; }        // -> m/s^2/sqrt(Hz)

ImuSpec crista() {
  // Cloud Cap Crista (seed 004): range +-300 deg/s, +-10 g (Crista ICD 2004); noise from its sensor class
  // (ADXRS300-class gyro 0.1 deg/s/sqrt(Hz), ADXL210-class accel 200 ug/sqrt(Hz)); bias figures assumed.
  ImuSpec s;
  s.name = "crista";
  s.gyro_arw = deg_per_s_sqrt_hz(0.1);
  s.accel_vrw = micro_g_sqrt_hz(200.0);
  s.gyro_bias_instability = deg_per_hr(100.0);
  s.gyro_bias_tau_s = 300.0;
  s.gyro_bias_initial = deg_per_s(0.5);
  s.accel_bias_instability = milli_g(2.0);
  s.accel_bias_tau_s = 300.0;
  s.accel_bias_initial = milli_g(30.0);
  s.gyro_scale_sigma = 0.01;
  s.accel_scale_sigma = 0.01;
  s.gyro_range = deg_per_s(300.0);
  s.accel_range = 10.0 * kG0;
  return s;
}

ImuSpec hg1700() {
  // Honeywell HG1700AG58 (tactical): ARW 0.125 deg/sqrt(h), gyro bias 1 deg/h, accel bias 1 mg,
  // VRW 0.0198 m/s/sqrt(h) (as tabulated in the U. Calgary PLAN-group theses for the HG1700 used in seed 004).
  ImuSpec s;
  s.name = "hg1700";
  s.gyro_arw = deg_per_sqrt_hr(0.125);
  s.accel_vrw = mps_per_sqrt_hr(0.0198);
  s.gyro_bias_instability = deg_per_hr(1.0);
  s.gyro_bias_tau_s = 3600.0;
  s.gyro_bias_initial = deg_per_hr(1.0);
  s.accel_bias_instability = milli_g(1.0);
  s.accel_bias_tau_s = 3600.0;
  s.accel_bias_initial = milli_g(1.0);
  s.gyro_scale_sigma = 150e-6;
  s.accel_scale_sigma = 300e-6;
  s.gyro_range = deg_per_s(1000.0);
  s.accel_range = 50.0 * kG0;
  return s;
}

ImuSpec gx5_25() {
  // LORD MicroStrain 3DM-GX5-25 datasheet: gyro +-300 deg/s, noise density 0.005 deg/s/sqrt(Hz) (ARW 0.3 deg/sqrt(h)),
  // bias instability 8 deg/h; accel +-8 g, noise density 25 ug/sqrt(Hz), bias instability 0.04 mg.
  ImuSpec s;
  s.name = "gx5_25";
  s.gyro_arw = deg_per_s_sqrt_hz(0.005);
  s.accel_vrw = micro_g_sqrt_hz(25.0);
  s.gyro_bias_instability = deg_per_hr(8.0);
  s.gyro_bias_tau_s = 100.0;
  s.gyro_bias_initial = deg_per_s(0.04);
  s.accel_bias_instability = milli_g(0.04);
  s.accel_bias_tau_s = 100.0;
  s.accel_bias_initial = milli_g(2.0);
  s.gyro_scale_sigma = 0.0005;
  s.accel_scale_sigma = 0.0005;
  s.gyro_range = deg_per_s(300.0);
  s.accel_range = 8.0 * kG0;
  return s;
}

ImuSpec ngimu() {
  // x-io NGIMU: gyro +-2000 deg/s, accel +-16 g (NGIMU user manual); noise of its consumer-grade MEMS class
  // (0.01 deg/s/sqrt(Hz), 300 ug/sqrt(Hz)) and bias figures assumed.
  ImuSpec s;
  s.name = "ngimu";
  s.gyro_arw = deg_per_s_sqrt_hz(0.01);
  s.accel_vrw = micro_g_sqrt_hz(300.0);
  s.gyro_bias_instability = deg_per_hr(20.0);
  s.gyro_bias_tau_s = 100.0;
  s.gyro_bias_initial = deg_per_s(0.5);
  s.accel_bias_instability = milli_g(0.5);
  s.accel_bias_tau_s = 100.0;
  s.accel_bias_initial = milli_g(40.0);
  s.gyro_scale_sigma = 0.005;
  s.accel_scale_sigma = 0.005;
  s.gyro_range = deg_per_s(2000.0);
  s.accel_range = 16.0 * kG0;
  return s;
}

}  // namespace

std::vector<std::string> ImuSpec::problems() const {
  std::vector<std::string> p;
  auto nonneg = [&](double v, const char* key) {
    if (!(v >= 0.0)) p.push_back(std::string(key) + " must be >= 0");
  };
  nonneg(gyro_arw, "gyro_arw");
  nonneg(accel_vrw, "accel_vrw");
  nonneg(gyro_bias_instability, "gyro_bias_instability");
  nonneg(gyro_bias_rw, "gyro_bias_rw");
  nonneg(gyro_bias_initial, "gyro_bias_initial");
  nonneg(accel_bias_instability, "accel_bias_instability");
  nonneg(accel_bias_rw, "accel_bias_rw");
  nonneg(accel_bias_initial, "accel_bias_initial");
  nonneg(gyro_scale_sigma, "gyro_scale_sigma");
  nonneg(accel_scale_sigma, "accel_scale_sigma");
  nonneg(gyro_g_sensitivity, "gyro_g_sensitivity");
  nonneg(gyro_range, "gyro_range");
  nonneg(accel_range, "accel_range");
  if (gyro_bias_instability > 0.0 && !(gyro_bias_tau_s > 0.0))
    p.push_back("gyro_bias_tau_s must be > 0 when gyro_bias_instability is given");
  if (accel_bias_instability > 0.0 && !(accel_bias_tau_s > 0.0))
    p.push_back("accel_bias_tau_s must be > 0 when accel_bias_instability is given");
  return p;
}

std::vector<std::string> imu_spec_preset_names() { return {"crista", "hg1700", "gx5_25", "ngimu"}; }

Expected<ImuSpec> imu_spec_preset(const std::string& name) {
  if (name == "crista") return crista();
  if (name == "hg1700") return hg1700();
  if (name == "gx5_25") return gx5_25();
  if (name == "ngimu") return ngimu();
  std::string all;
  for (const auto& n : imu_spec_preset_names()) all += (all.empty() ? "" : ", ") + n;
  return make_error("unknown IMU spec preset '" + name + "' (expected one of " + all + ")");
}

}  // namespace pednav::ins
