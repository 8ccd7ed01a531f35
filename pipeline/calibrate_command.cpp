// SPDX-License-Identifier: BSD-2-Clause
// `pednav calibrate` (pipeline/calibrate_command.hpp).
#include "pipeline/calibrate_command.hpp"

#include <fmt/format.h>

#include <filesystem>

#include "core/geodesy.hpp"
#include "io/atomic_file.hpp"
#include "io/imu_csv.hpp"

namespace pednav::pipeline {

std::string calibration_yaml(const SelfCalibration& s, const std::string& imu_file) {
  const ins::ImuCalibration& c = s.calibration;
  const ins::ImuSpec& p = s.spec;
  const double dps = kRadToDeg;
  std::string y;
  y += fmt::format("# pednav calibrate: {}\n", imu_file);
  y += fmt::format("# {} samples, {:.1f} s at {:.2f} Hz (jitter {:.2g} s); still {:.1f} s in {} periods; {} footfalls\n",
                   c.samples, c.duration_s, c.rate_hz, c.dt_jitter_s, c.still_s, c.still.size(), c.footfalls);
  for (const auto& w : c.warnings) y += "# warning: " + w + "\n";
  y += "# Paste into a run configuration, or write `spec: auto` / `shoe_threshold: auto` to have every run do this.\n";
  y += "imu:\n  spec:\n";
  const std::string noise_from =
      c.noise_estimated ? fmt::format("measured {:.3g}", c.gyro_noise_density.maxCoeff() * kRadToDeg * 60.0)
                        : std::string("no still period");
  y += fmt::format("    gyro_arw_deg_per_sqrt_hr: {:.6g}      # max(white noise of the rate at rest, worst axis: {}; "
                   "floor 2.12 for a foot's unmodelled errors)\n",
                   p.gyro_arw * kRadToDeg * 60.0, noise_from);
  const std::string vrw_from = c.noise_estimated
                                   ? fmt::format("measured {:.3g}", c.accel_noise_density.maxCoeff() * 60.0)
                                   : std::string("no still period");
  y += fmt::format("    accel_vrw_mps_per_sqrt_hr: {:.6g}     # max(white noise of the specific force at rest: {}; "
                   "floor 2.12)\n",
                   p.accel_vrw * 60.0, vrw_from);
  const std::string window = fmt::format("[{:.4f}, {:.4f}, {:.4f}] deg/s at {:.1f}-{:.1f} s", c.gyro_bias_radps.x() * dps,
                                         c.gyro_bias_radps.y() * dps, c.gyro_bias_radps.z() * dps, c.bias_window_t0_s,
                                         c.bias_window_t0_s + c.bias_window_s);
  y += fmt::format("    gyro_bias_initial_deg_per_s: {:.6g}  # {}; floor 0.02\n", p.gyro_bias_initial * dps,
                   !c.bias_estimated        ? std::string("the bias was not measured")
                   : c.bias_window_moving ? "the first still period turned (" + window + ", k " +
                                                fmt::format("{:.2f}", c.bias_window_rotation_k) + "): not a bias"
                                          : "covers the bias of the first still period (" + window + ")");
  y += fmt::format("    gyro_bias_instability_deg_per_hr: {:.6g}  # generic MEMS (not measurable in a short log)\n",
                   p.gyro_bias_instability * kRadToDeg * 3600.0);
  y += fmt::format("    gyro_bias_tau_s: {:.6g}\n", p.gyro_bias_tau_s);
  y += fmt::format("    accel_bias_initial_mg: {:.6g}             # generic MEMS (a still period does not separate it "
                   "from tilt)\n",
                   p.accel_bias_initial / 9.80665 * 1e3);
  y += fmt::format("    accel_bias_instability_mg: {:.6g}\n", p.accel_bias_instability / 9.80665 * 1e3);
  y += fmt::format("    accel_bias_tau_s: {:.6g}\n", p.accel_bias_tau_s);
  y += fmt::format("    gyro_range_deg_per_s: {:.6g}              # {}\n", p.gyro_range * dps,
                   c.gyro_plateau_radps > 0.0 ? "the saturation plateau found" : "0 = unknown (no plateau found)");
  y += fmt::format("    accel_range_g: {:.6g}                     # {}\n", p.accel_range / 9.80665,
                   c.accel_plateau_mps2 > 0.0 ? "the saturation plateau found" : "0 = unknown (no plateau found)");
  y += "zupt:\n";
  if (s.threshold.from_split) {
    y += fmt::format("  shoe_threshold: {:.6g}   # the two-class split of the log's SHOE statistic ({:.4g}, capped at "
                     "{:.3g}; docs/zupt.md eq. 6.2), above the level at rest {:.4g} ({}) + the motion allowance\n",
                     s.threshold.threshold, s.threshold.split, s.threshold.cap, s.threshold.rest,
                     s.threshold.from_still ? "99th percentile over the still periods" : "5th percentile: no still period");
  } else {
    const std::string split = s.threshold.cap > 0.0 ? fmt::format("two-class split {:.4g} lower", s.threshold.split)
                                                    : std::string("two-class split off");
    y += fmt::format("  shoe_threshold: {:.6g}   # the SHOE statistic at rest ({:.4g}, {}) + the motion allowance {:.3g}, "
                     "with the configured sigmas ({})\n",
                     s.threshold.threshold, s.threshold.rest,
                     s.threshold.from_still ? "99th percentile over the still periods" : "5th percentile: no still period",
                     s.threshold.threshold - s.threshold.rest, split);
  }
  y += fmt::format("  shoe_adaptive_factor: {:g}   # raised to {:g} x the local minimum next to a swing (docs/zupt.md §1)\n",
                   ins::kAutoAdaptiveFactor, ins::kAutoAdaptiveFactor);
  y += fmt::format("  shoe_adaptive_window_s: {:g}\n", ins::kAutoAdaptiveWindowS);
  y += fmt::format("  shoe_adaptive_min_peak_rate_deg_per_s: {:g}\n", ins::kAutoAdaptiveMinPeakDegPerS);
  y += fmt::format("# gravity: {} ({} up, {:.1f} deg tilt, |f| = {:.4f} m/s^2); gait: {:.1f} strides/min, stance "
                   "share {:.2f}, peak rate {:.0f} deg/s (p99)\n",
                   c.gravity_estimated ? "measured" : "not measured", c.up_axis.empty() ? "?" : c.up_axis, c.tilt_deg,
                   c.gravity_mps2, c.stride_cadence_per_min, c.stance_share, c.gyro_p99_radps * kRadToDeg);
  return y;
}

Expected<CalibrateResult> run_calibrate_command(const io::RunConfig& config, const std::string& out_dir) {
  if (!config.imu.has_format) return make_error(config.source_file + ": imu.format: required to read the IMU log");
  if (config.imu.file.empty()) return make_error(config.source_file + ": imu.file: required");
  auto log = io::read_imu_csv(config.imu.file, config.imu.format);
  if (!log) return log.error();
  io::RunConfig c = config;
  c.imu.spec_auto = true;
  c.zupt.shoe_threshold_auto = true;
  CalibrateResult r;
  r.self = *resolve_self_calibration(c, *log);
  const ins::ImuCalibration& k = r.self.calibration;
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return make_error(out_dir + ": cannot create the output folder: " + ec.message());
  const std::filesystem::path out(out_dir);
  nlohmann::ordered_json j = self_calibration_json(r.self);
  j["imu_file"] = config.imu.file;
  if (auto ok = io::write_file_atomic((out / "calibration.json").string(), j.dump(2) + "\n"); !ok) return ok.error();
  if (auto ok = io::write_file_atomic((out / "calibration.yaml").string(), calibration_yaml(r.self, config.imu.file));
      !ok) {
    return ok.error();
  }
  r.summary = fmt::format("{}: {:.1f} s at {:.1f} Hz; still {:.1f} s", config.imu.file, k.duration_s, k.rate_hz, k.still_s);
  if (k.bias_estimated) {
    r.summary += fmt::format("; {} [{:.3f}, {:.3f}, {:.3f}] deg/s",
                             k.bias_window_moving ? "first still period turning at" : "gyro bias",
                             k.gyro_bias_radps.x() * kRadToDeg, k.gyro_bias_radps.y() * kRadToDeg,
                             k.gyro_bias_radps.z() * kRadToDeg);
  }
  if (k.gravity_estimated) r.summary += fmt::format("; {} up ({:.1f} deg tilt)", k.up_axis, k.tilt_deg);
  if (k.noise_estimated) {
    r.summary += fmt::format("; ARW {:.3g} deg/sqrt(h), VRW {:.3g} m/s/sqrt(h)",
                             k.gyro_noise_density.maxCoeff() * kRadToDeg * 60.0, k.accel_noise_density.maxCoeff() * 60.0);
  }
  r.summary += fmt::format("; {} footfalls ({:.1f}/min); SHOE threshold {:.3g}", k.footfalls, k.stride_cadence_per_min,
                           r.self.threshold.threshold);
  return r;
}

}  // namespace pednav::pipeline
