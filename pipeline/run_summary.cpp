// SPDX-License-Identifier: BSD-2-Clause
// summary.json sections of `pednav run` (pipeline/run_summary.hpp).
#include "pipeline/run_summary.hpp"

#include <map>
#include <optional>
#include <string>

#include "core/geodesy.hpp"
#include "fusion/ambiguity.hpp"

namespace pednav::pipeline {

// read = used + rejected (by reason) + skipped (by reason), for IMU rows and rover measurements (docs/robustness.md).
nlohmann::ordered_json accounting_json(const io::ImuLog& imu, const RunInputs& data, const fusion::EngineSummary& sum, bool tc) {
  nlohmann::ordered_json a;
  std::map<std::string, long> imu_rejected = sum.imu_rejected;
  if (imu.report.bad_rows) imu_rejected["unparsable_or_non_finite_row"] += imu.report.bad_rows;
  if (imu.report.duplicates_dropped) imu_rejected["duplicate_time"] += imu.report.duplicates_dropped;
  std::map<std::string, long> imu_skipped = sum.imu_skipped;
  if (imu.report.truncated_rows) imu_skipped["truncated_last_row"] += imu.report.truncated_rows;
  a["imu_samples"] = {{"read", imu.report.rows},
                      {"used", sum.imu_samples_used},
                      {"rejected", imu_rejected},
                      {"skipped", imu_skipped}};
  if (!tc) return a;
  std::map<std::string, long> rejected = sum.code_used_rejected;
  const long used = rejected.count("used") ? rejected.at("used") : 0;
  rejected.erase("used");
  a["gnss_measurements"] = {{"read", sum.gnss_measurements},
                            {"used", used},
                            {"rejected", rejected},
                            {"skipped", sum.gnss_skipped}};
  if (data.rover) {
    a["rover_obs"] = {{"truncated", data.rover->stats.truncated},
                      {"last_epoch_dropped", data.rover->stats.last_epoch_dropped}};
  }
  if (data.base) {
    a["base_obs"] = {{"truncated", data.base->stats.truncated},
                     {"last_epoch_dropped", data.base->stats.last_epoch_dropped}};
  }
  return a;
}

nlohmann::json imu_estimate_json(const fusion::ImuEstimate& ie) {
  auto arr = [](const Eigen::Vector3d& v, double scale) {
    return nlohmann::json::array({v.x() * scale, v.y() * scale, v.z() * scale});
  };
  nlohmann::json e = {{"gyro_bias_deg_per_h", arr(ie.value.b_g, kRadToDeg * 3600.0)},
                      {"gyro_bias_sd_deg_per_h", arr(ie.sd.b_g, kRadToDeg * 3600.0)},
                      {"accel_bias_mg", arr(ie.value.b_a, 1e3 / 9.80665)},
                      {"accel_bias_sd_mg", arr(ie.sd.b_a, 1e3 / 9.80665)}};
  if (ie.gyro_scale) {
    e["gyro_scale_ppm"] = arr(ie.value.s_g, 1e6);
    e["gyro_scale_sd_ppm"] = arr(ie.sd.s_g, 1e6);
    e["gyro_scale_compensation_ppm"] = arr(ie.gyro_scale_compensation, 1e6);
  }
  if (ie.accel_scale) {
    e["accel_scale_ppm"] = arr(ie.value.s_a, 1e6);
    e["accel_scale_sd_ppm"] = arr(ie.sd.s_a, 1e6);
    e["accel_scale_compensation_ppm"] = arr(ie.accel_scale_compensation, 1e6);
  }
  if (ie.g_sensitivity) {  // consider states (never estimated): the σ carried, rows of G_g in deg/s per g
    const double k = kRadToDeg * 9.80665;
    nlohmann::json rows = nlohmann::json::array();
    for (int i = 0; i < 3; ++i) rows.push_back({ie.sd.G_g(i, 0) * k, ie.sd.G_g(i, 1) * k, ie.sd.G_g(i, 2) * k});
    e["gyro_g_sensitivity_consider_sd_deg_per_s_per_g"] = rows;
  }
  return e;
}

nlohmann::ordered_json zupt_json(const io::RunConfig& c, const fusion::EngineSummary& sum) {
  nlohmann::ordered_json z = {{"detector", c.zupt.detector}, {"form", c.zupt.form}, {"updates", sum.zupt_updates},
                      {"stance_samples", sum.zupt_samples}, {"zaru_updates", sum.zaru_updates},
                      {"zaru_rejected_by_gate", sum.zaru_rejected},
                      {"short_stance_interval_ends", sum.zupt_short_stance_interval_ends}};
  // The velocity rows' NIS, χ²(3) when the model fits (docs/fusion.md §15): mean and share beyond the 99 % quantile,
  // over all ZUPTs and over the first of each stance.
  auto share = [](long k, long n) {
    return n > 0 ? nlohmann::json(static_cast<double>(k) / static_cast<double>(n)) : nlohmann::json(nullptr);
  };
  auto mean = [](double s, long n) { return n > 0 ? nlohmann::json(s / static_cast<double>(n)) : nlohmann::json(nullptr); };
  z["innovation_nis"] = {{"mean", mean(sum.zupt_nis_sum, sum.zupt_updates)},
                         {"above_p99_share", share(sum.zupt_nis_above_p99, sum.zupt_updates)},
                         {"stances", sum.zupt_first_of_stance},
                         {"first_of_stance_mean", mean(sum.zupt_first_nis_sum, sum.zupt_first_of_stance)},
                         {"first_of_stance_above_p99_share", share(sum.zupt_first_nis_above_p99, sum.zupt_first_of_stance)}};
  return z;
}

// summary.json `carrier` (docs/carrier.md §6): output epochs by status, fix rate, time to first fix, the re-fix time
// after each span without a fixed epoch of at least 10 s, and the filter's counters.
nlohmann::json carrier_json(const fusion::EngineSummary& sum, const std::vector<fusion::EpochOutput>& epochs) {
  nlohmann::json c;
  std::map<std::string, long> by_status;
  std::optional<GpsTime> first, first_fix, last_fix;
  std::vector<double> refix;
  for (const auto& e : epochs) {
    const auto st = static_cast<fusion::SolutionStatus>(e.solution_status);
    ++by_status[fusion::solution_status_name(st)];
    if (!first) first = e.t;
    if (st != fusion::SolutionStatus::kFixed) continue;
    if (!first_fix) first_fix = e.t;
    if (last_fix && e.t - *last_fix >= 10.0) refix.push_back(e.t - *last_fix);
    last_fix = e.t;
  }
  c["used"] = true;
  c["output_epochs_by_status"] = by_status;
  c["fix_rate_pct"] = epochs.empty() ? 0.0 : 100.0 * by_status["fixed"] / static_cast<double>(epochs.size());
  c["time_to_first_fix_s"] = first_fix ? nlohmann::json(*first_fix - *first) : nlohmann::json(nullptr);
  c["gaps_between_fixed_epochs_s"] = refix;
  const auto& k = sum.carrier;
  c["gnss_epochs_with_phase"] = k.epochs_with_phase;
  c["fix_attempts"] = k.fix_attempts;
  c["not_fixed"] = k.not_fixed;
  c["fixes_rejected_by_validation"] = k.fixes_rejected_by_validation;
  c["wrong_fix_detections"] = k.wrong_fix_detections;
  c["integer_constraints"] = k.holds;
  c["phase_without_free_slot"] = k.no_free_slot;
  nlohmann::json slips;
  for (int i = 0; i < static_cast<int>(gnss::SlipReason::kCount); ++i) {
    slips[gnss::slip_reason_name(static_cast<gnss::SlipReason>(i))] = k.slips[i];
  }
  c["slips"] = slips;
  // Antenna states (docs/carrier.md §10): foot-to-antenna tie halves (position, velocity) inside the χ² gate, and
  // beyond it (applied with their noise inflated, eq. 10.4).
  c["antenna_ties"] = {{"consistent", k.antenna_ties}, {"inflated", k.antenna_ties_inflated}};
  return c;
}

}  // namespace pednav::pipeline
