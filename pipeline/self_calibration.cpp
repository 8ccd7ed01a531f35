// SPDX-License-Identifier: BSD-2-Clause
// `auto` IMU spec and SHOE threshold from the log (pipeline/self_calibration.hpp).
#include "pipeline/self_calibration.hpp"

#include <cmath>

#include "core/geodesy.hpp"
#include "io/hmm_model_io.hpp"
#include "ins/zupt_detector.hpp"

namespace pednav::pipeline {
namespace {

nlohmann::json vec(const Eigen::Vector3d& v, double scale) {
  return nlohmann::json::array({v.x() * scale, v.y() * scale, v.z() * scale});
}

// Gait-adaptive raise of the auto threshold next to a swing (docs/zupt.md §1, §6) unless configured:
// ins::kAutoAdaptiveFactor, ins::kAutoAdaptiveWindowS, ins::kAutoAdaptiveMinPeakDegPerS.
// ... and, unless configured, every stance sample (no edge skip) with the ZARU innovation gate (docs/fusion.md §5.3):
// an auto threshold keeps the slow rolling of a foot in its stances, which a ZARU would turn into a gyro bias.
// Chosen on the tuning subset (median pednav / PyShoe per-trial tuned): 0.89x with both, 0.98x with the gate only,
// 2.83x with the edges only, 1.74x with neither (measured 2026-12-05, scripts/pyshoe_cv --tuning-only, with the first
// auto knobs 1.5 / 3 / 180 °/s; kept when scripts/pyshoe_loso re-chose those).
constexpr double kAutoEdgeS = 0.0;
constexpr double kAutoZaruGateProbability = 0.999;

}  // namespace

std::optional<SelfCalibration> resolve_self_calibration(io::RunConfig& c, const io::ImuLog& log) {
  if (!c.imu.spec_auto && !c.zupt.shoe_threshold_auto) return std::nullopt;
  SelfCalibration s;
  s.calibration = ins::calibrate_imu(log.samples);
  if (c.imu.spec_auto) {
    s.spec_auto = true;
    s.spec = ins::spec_from_calibration(s.calibration);
    c.imu.spec = s.spec;
    c.imu.spec_auto = false;  // config.resolved.yaml carries the numbers the run used
    c.imu.spec_preset.clear();
    c.imu.spec.name = "inline";
    // The ZARU's noise per sample is at least the gyro's measured white noise per sample (a noisy sensor at a high
    // rate would otherwise have every ZARU gated or, without the gate, its noise taken for a bias).
    if (s.calibration.noise_estimated && !c.zupt.zaru_sigma_given) {
      const double per_sample = s.calibration.gyro_noise_density.maxCoeff() * std::sqrt(s.calibration.rate_hz);
      c.zupt.zaru_sigma_radps = std::max(c.zupt.zaru_sigma_radps, per_sample);
    }
  }
  if (c.zupt.shoe_threshold_auto) {
    s.threshold_auto = true;
    const ins::ZuptDetectorOptions zo = io::zupt_detector_options(c.zupt);
    ins::AutoThresholdOptions ao;
    ao.motion = c.zupt.shoe_threshold_motion;
    ao.two_class_cap = c.zupt.shoe_threshold_two_class_cap;
    s.threshold = ins::auto_shoe_threshold(ins::shoe_statistic(log.samples, zo), s.calibration, ao);
    c.zupt.shoe_threshold = s.threshold.threshold;
    c.zupt.shoe_threshold_auto = false;
    if (c.zupt.shoe_adaptive_factor <= 0.0) {
      c.zupt.shoe_adaptive_factor = ins::kAutoAdaptiveFactor;
      c.zupt.shoe_adaptive_window_s = ins::kAutoAdaptiveWindowS;
      if (c.zupt.shoe_adaptive_min_peak_radps <= 0.0) {
        c.zupt.shoe_adaptive_min_peak_radps = ins::kAutoAdaptiveMinPeakDegPerS * kDegToRad;
      }
    }
    if (!c.zupt.edge_s_given) c.zupt.edge_s = kAutoEdgeS;
    if (!c.zupt.zaru_gate_given) c.zupt.zaru_gate_probability = kAutoZaruGateProbability;
  }
  return s;
}

nlohmann::ordered_json calibration_json(const ins::ImuCalibration& c) {
  const double dph = kRadToDeg * 3600.0;
  const double to_deg_per_sqrt_h = kRadToDeg * 60.0;  // rad/√s -> °/√h
  nlohmann::ordered_json j;
  j["samples"] = c.samples;
  j["duration_s"] = c.duration_s;
  j["rate_hz"] = c.rate_hz;
  j["dt_median_s"] = c.dt_median_s;
  j["dt_jitter_s"] = c.dt_jitter_s;
  j["gaps"] = c.gaps;
  j["repeated_samples"] = c.repeated_samples;
  j["gyro_abs_max_deg_per_s"] = vec(c.gyro_abs_max_radps, kRadToDeg);
  j["accel_abs_max_g"] = vec(c.accel_abs_max_mps2, 1.0 / 9.80665);
  j["gyro_p99_deg_per_s"] = c.gyro_p99_radps * kRadToDeg;
  j["accel_p99_g"] = c.accel_p99_mps2 / 9.80665;
  j["gyro_saturation_deg_per_s"] = c.gyro_plateau_radps * kRadToDeg;
  j["accel_saturation_g"] = c.accel_plateau_mps2 / 9.80665;
  j["gyro_saturated_samples"] = c.gyro_saturated_samples;
  j["accel_saturated_samples"] = c.accel_saturated_samples;
  nlohmann::json still = nlohmann::json::array();
  for (const auto& p : c.still) still.push_back({{"t0_s", p.t0_s}, {"duration_s", p.duration_s}});
  j["still_periods"] = still;
  j["still_s"] = c.still_s;
  j["bias_estimated"] = c.bias_estimated;
  if (c.bias_estimated) {
    j["gyro_bias_deg_per_h"] = vec(c.gyro_bias_radps, dph);
    j["gyro_bias_sd_deg_per_h"] = vec(c.gyro_bias_sd_radps, dph);
    j["bias_window"] = {{"t0_s", c.bias_window_t0_s},
                        {"duration_s", c.bias_window_s},
                        {"tilt_rate_deg_per_h", c.bias_window_tilt_rate_radps * dph},
                        {"predicted_tilt_rate_deg_per_h", c.bias_window_predicted_rate_radps * dph},
                        {"tilt_rate_sd_deg_per_h", c.bias_window_tilt_rate_sd_radps * dph},
                        {"rotation_k", c.bias_window_rotation_k},
                        {"moving", c.bias_window_moving}};
  }
  j["gravity_estimated"] = c.gravity_estimated;
  if (c.gravity_estimated) {
    j["gravity_mps2"] = c.gravity_mps2;
    j["up_axis"] = c.up_axis;
    j["up_in_sensor_axes"] = vec(c.up_b, 1.0);
    j["tilt_deg"] = c.tilt_deg;
  }
  j["noise_estimated"] = c.noise_estimated;
  if (c.noise_estimated) {
    j["gyro_arw_deg_per_sqrt_hr"] = vec(c.gyro_noise_density, to_deg_per_sqrt_h);
    j["accel_vrw_mps_per_sqrt_hr"] = vec(c.accel_noise_density, 60.0);
  }
  j["gait"] = {{"footfalls", c.footfalls},
               {"walking_s", c.walking_s},
               {"stride_cadence_per_min", c.stride_cadence_per_min},
               {"stance_share", c.stance_share}};
  j["warnings"] = c.warnings;
  return j;
}

nlohmann::ordered_json self_calibration_json(const SelfCalibration& s) {
  nlohmann::ordered_json j;
  j["calibration"] = calibration_json(s.calibration);
  if (s.spec_auto) {
    j["spec"] = {{"gyro_arw_deg_per_sqrt_hr", s.spec.gyro_arw * kRadToDeg * 60.0},
                 {"accel_vrw_mps_per_sqrt_hr", s.spec.accel_vrw * 60.0},
                 {"gyro_bias_initial_deg_per_s", s.spec.gyro_bias_initial * kRadToDeg},
                 {"gyro_range_deg_per_s", s.spec.gyro_range * kRadToDeg},
                 {"accel_range_g", s.spec.accel_range / 9.80665}};
  }
  if (s.threshold_auto) {
    j["shoe_threshold"] = {{"rest", s.threshold.rest},
                           {"threshold", s.threshold.threshold},
                           {"rest_from", s.threshold.from_still ? "still periods" : "5th percentile (no still period)"},
                           {"two_class_split", s.threshold.split},
                           {"two_class_cap", s.threshold.cap},
                           {"from", s.threshold.from_split ? "two-class split (capped)" : "rest + motion allowance"}};
  }
  return j;
}

}  // namespace pednav::pipeline
