// SPDX-License-Identifier: BSD-2-Clause
// Checks of a finished run against what a foot-mounted IMU on a walker produces (pipeline/run_warnings.hpp).
#include "pipeline/run_warnings.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <utility>

#include "core/geodesy.hpp"
#include "eval/trajectory.hpp"

namespace pednav::pipeline {
namespace {

constexpr double kChi2Dof2P99 = 9.2103;  // χ²(2) 99 % quantile: −2 ln 0.01
constexpr double kStandardGravity = 9.80665;  // [m/s²]

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Horizontal (north, east) difference a − b [m] in the local level frame at a.
Eigen::Vector2d horizontal_difference(const Eigen::Vector3d& a_e, const Eigen::Vector3d& b_e) {
  const Geodetic llh = geodetic_from_ecef(a_e);
  const Eigen::Vector3d d_n = R_e_n(llh.lat, llh.lon).transpose() * (a_e - b_e);
  return d_n.head<2>();
}

// Forward and smoothed solutions beyond their own σ's (eq. 15.1).
void check_disagreement(const fusion::EngineResult& r, const RunWarningLimits& l, std::vector<RunWarning>& out) {
  if (r.smoothed.size() != r.epochs.size() || static_cast<int>(r.epochs.size()) < l.disagreement_min_epochs) return;
  int n = 0, beyond = 0;
  for (size_t i = 0; i < r.epochs.size(); ++i) {
    const auto& f = r.epochs[i];
    const auto& s = r.smoothed[i];
    const Eigen::Vector2d d = horizontal_difference(f.nav.p_eb_e, s.nav.p_eb_e);
    Eigen::Matrix2d C = (f.cov_p_n - s.cov_p_n).topLeftCorner<2, 2>();
    Eigen::LLT<Eigen::Matrix2d> llt(C);
    if (llt.info() != Eigen::Success || C.diagonal().minCoeff() < 1e-12) {
      C = f.cov_p_n.topLeftCorner<2, 2>();  // the smoother added nothing here: the forward σ alone
      llt.compute(C);
      if (llt.info() != Eigen::Success) continue;
    }
    ++n;
    beyond += d.dot(llt.solve(d)) > kChi2Dof2P99;
  }
  if (n < l.disagreement_min_epochs) return;
  const double share = static_cast<double>(beyond) / n;
  if (share <= l.disagreement_max_share) return;
  out.push_back({"forward_smoothed_disagree",
                 fmt::format("forward and smoothed positions differ beyond their σ's at {:.1f} % of {} epochs "
                             "(1 % expected; limit {:.0f} %)", 100.0 * share, n, 100.0 * l.disagreement_max_share),
                 100.0 * share, 100.0 * l.disagreement_max_share,
                 "the filter's IMU model does not fit this sensor: try imu.spec: auto (or pednav calibrate), and "
                 "check imu.format's units, axes and rate"});
}

// Stances of the forward output: mean position and mid time of each run of ZUPT epochs.
struct Stance {
  Eigen::Vector3d p_e;
  double t_s;
};

std::vector<Stance> stances(const fusion::EngineResult& r) {
  std::vector<Stance> out;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double t0 = 0.0, t1 = 0.0;
  int n = 0;
  for (const auto& e : r.epochs) {
    if (e.zupt) {
      if (n == 0) t0 = e.t.tow_s();
      t1 = e.t.tow_s();
      sum += e.nav.p_eb_e;
      ++n;
    } else if (n > 0) {
      out.push_back({sum / n, 0.5 * (t0 + t1)});
      sum.setZero();
      n = 0;
    }
  }
  if (n > 0) out.push_back({sum / n, 0.5 * (t0 + t1)});
  return out;
}

double track_length_m(const fusion::EngineResult& r) {
  double d = 0.0;
  for (size_t i = 1; i < r.epochs.size(); ++i) d += (r.epochs[i].nav.p_eb_e - r.epochs[i - 1].nav.p_eb_e).norm();
  return d;
}

// Stance share, step length and cadence of a walk (eqs. 15.2-15.4).
void check_gait(const fusion::EngineResult& r, const RunWarningLimits& l, std::vector<RunWarning>& out) {
  const auto& sum = r.summary;
  const double track = track_length_m(r);
  if (sum.imu_samples_used <= 0 || track < l.moving_track_min_m) return;
  const double share = static_cast<double>(sum.zupt_samples) / static_cast<double>(sum.imu_samples_used);
  if (share < l.stance_share_min || share > l.stance_share_max) {
    const bool low = share < l.stance_share_min;
    out.push_back({"stance_share",
                   fmt::format("stance detected on {:.1f} % of the samples over a {:.0f}-m track (a walking foot: "
                               "{:.0f}-{:.0f} %)", 100.0 * share, track, 100.0 * l.stance_share_min,
                               100.0 * l.stance_share_max),
                   100.0 * share, 100.0 * (low ? l.stance_share_min : l.stance_share_max),
                   low ? "no stances: is the IMU on the foot? Otherwise raise zupt.shoe_threshold (or use auto)"
                       : "stance almost everywhere: lower zupt.shoe_threshold (or use auto), check imu.format's "
                         "units"});
  }
  std::vector<double> intervals;
  for (size_t i = 1; i < r.epochs.size(); ++i) intervals.push_back(r.epochs[i].t - r.epochs[i - 1].t);
  if (intervals.empty() || median(intervals) > l.gait_output_interval_max_s) return;
  const std::vector<Stance> st = stances(r);
  std::vector<double> strides, periods;
  for (size_t i = 1; i < st.size(); ++i) {
    const double dt = st[i].t_s - st[i - 1].t_s;
    const double d = (st[i].p_e - st[i - 1].p_e).norm();
    if (dt <= 0.0 || dt > l.max_stride_s || d < 0.05) continue;  // a pause or a shuffle on the spot
    strides.push_back(d);
    periods.push_back(dt);
  }
  if (strides.size() < 5) return;
  const double step = 0.5 * median(strides);
  if (step < l.step_length_min_m || step > l.step_length_max_m) {
    out.push_back({"step_length",
                   fmt::format("median step {:.2f} m over {} strides (limits {:.1f}-{:.1f} m)", step, strides.size(),
                               l.step_length_min_m, l.step_length_max_m),
                   step, step < l.step_length_min_m ? l.step_length_min_m : l.step_length_max_m,
                   step < l.step_length_min_m
                       ? "stances inside the swing (a threshold too high: try zupt.shoe_threshold: auto) or a scale "
                         "error (imu.format's accelerometer unit, the declared rate)"
                       : "a scale error: check imu.format's accelerometer unit and the declared rate"});
  }
  const double cadence = 1.0 / median(periods);
  if (cadence < l.cadence_min_hz || cadence > l.cadence_max_hz) {
    out.push_back({"cadence",
                   fmt::format("{:.2f} strides/s (walking and running: {:.1f}-{:.1f})", cadence, l.cadence_min_hz,
                               l.cadence_max_hz),
                   cadence, cadence < l.cadence_min_hz ? l.cadence_min_hz : l.cadence_max_hz,
                   "the time axis does not fit a gait: check the declared rate or time unit of imu.format"});
  }
}

// The forward filter's final gyro bias against the spec's bias σ (eq. 15.5).
void check_gyro_bias(const fusion::EngineResult& r, const ins::ImuSpec& spec, const RunWarningLimits& l,
                     std::vector<RunWarning>& out) {
  const double sigma = std::hypot(spec.gyro_bias_initial, spec.gyro_bias_instability);
  if (!(sigma > 0.0)) return;
  const double worst = r.summary.imu_estimate.value.b_g.cwiseAbs().maxCoeff();
  if (worst <= l.gyro_bias_sigmas * sigma) return;
  const double to_deg_h = kRadToDeg * 3600.0;
  out.push_back({"gyro_bias",
                 fmt::format("gyro bias estimate {:.1f} °/h is beyond {:.0f} σ of the spec ({:.1f} °/h)",
                             worst * to_deg_h, l.gyro_bias_sigmas, sigma * to_deg_h),
                 worst * to_deg_h, l.gyro_bias_sigmas * sigma * to_deg_h,
                 "the spec's bias σ is too small for this sensor, or the gyro unit is wrong: try imu.spec: auto"});
}

// The first ZUPT of each stance meets the error the swing accumulated: its NIS is χ²(3) when the spec's noise and the
// ZUPT σ describe the foot; the share beyond the 99 % quantile is 1 % then (eq. 15.8).
void check_zupt_innovations(const fusion::EngineResult& r, const RunWarningLimits& l, std::vector<RunWarning>& out) {
  const fusion::EngineSummary& s = r.summary;
  if (s.zupt_first_of_stance < l.zupt_nis_min_stances) return;
  const double share = static_cast<double>(s.zupt_first_nis_above_p99) / static_cast<double>(s.zupt_first_of_stance);
  if (share <= l.zupt_nis_max_share) return;
  out.push_back({"zupt_innovations",
                 fmt::format("the first ZUPT of {:.1f} % of {} stances is beyond the 99 % χ²(3) quantile of its "
                             "innovation (1 % expected; mean NIS {:.1f}, 3 expected)",
                             100.0 * share, s.zupt_first_of_stance,
                             s.zupt_first_nis_sum / static_cast<double>(s.zupt_first_of_stance)),
                 100.0 * share, 100.0 * l.zupt_nis_max_share,
                 "the swing errs more than the IMU model says (running, impacts, a spec from another sensor): try "
                 "imu.spec: auto, or a spec with larger gyro_arw/accel_vrw, or a larger zupt.sigma_mps"});
}

}  // namespace

std::vector<RunWarning> run_warnings(const fusion::EngineResult& result, const ins::ImuSpec& spec,
                                     const RunWarningLimits& limits) {
  std::vector<RunWarning> out;
  check_disagreement(result, limits, out);
  check_gait(result, limits, out);
  check_gyro_bias(result, spec, limits, out);
  check_zupt_innovations(result, limits, out);
  return out;
}

std::vector<RunWarning> imu_log_warnings(const std::vector<ins::ImuSample>& samples, const RunWarningLimits& l) {
  std::vector<RunWarning> out;
  if (samples.size() < 10) return out;
  std::vector<double> w, f, dt;
  w.reserve(samples.size());
  f.reserve(samples.size());
  dt.reserve(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    w.push_back(samples[i].omega_ib_b.norm());
    f.push_back(std::abs(samples[i].f_ib_b.norm() - kStandardGravity));
    if (i > 0) dt.push_back(samples[i].t - samples[i - 1].t);
  }
  const double w999 = eval::quantile(std::move(w), 0.999), f99 = eval::quantile(std::move(f), 0.99);
  if (w999 > l.gyro_max_plausible_radps) {
    out.push_back({"gyro_unit",
                   fmt::format("gyro rates reach {:.0f} rad/s (99.9th percentile; a foot's swing peaks at 5-15 rad/s, "
                               "limit {:.0f})", w999, l.gyro_max_plausible_radps),
                   w999, l.gyro_max_plausible_radps,
                   "data in deg/s declared rad_per_s? Check imu.format.gyro.unit (and the columns)"});
  } else if (w999 < l.gyro_min_walking_radps && f99 > l.accel_step_mps2) {
    out.push_back({"gyro_unit",
                   fmt::format("the accelerometer shows steps (| |f| - g | to {:.1f} m/s^2) but the gyro never exceeds "
                               "{:.3f} rad/s (limit {:.1f})", f99, w999, l.gyro_min_walking_radps),
                   w999, l.gyro_min_walking_radps,
                   "data in rad/s declared deg_per_s? Check imu.format.gyro.unit (and the columns)"});
  }
  const double dt_median = median(dt);
  if (dt_median > 0.0) {
    const double rate = 1.0 / dt_median;
    if (rate < l.rate_min_hz || rate > l.rate_max_hz) {
      out.push_back({"imu_rate",
                     fmt::format("{:.4g} Hz from the time column (limits {:.0f}-{:.0f} Hz)", rate, l.rate_min_hz,
                                 l.rate_max_hz),
                     rate, rate < l.rate_min_hz ? l.rate_min_hz : l.rate_max_hz,
                     "a wrong time unit? Check imu.format.time (unit s, ms, us, ns; base)"});
    }
  }
  return out;
}

nlohmann::ordered_json run_warnings_json(const std::vector<RunWarning>& warnings) {
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (const auto& w : warnings) {
    nlohmann::ordered_json o;
    o["code"] = w.code;
    o["message"] = w.message;
    o["value"] = w.value;
    o["limit"] = w.limit;
    o["hint"] = w.hint;
    a.push_back(o);
  }
  return a;
}

}  // namespace pednav::pipeline
