// SPDX-License-Identifier: BSD-2-Clause
// Self-calibration of an IMU log (ins/calibration.hpp, docs/ins.md §10).
#include "ins/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/geodesy.hpp"

namespace pednav::ins {
namespace {

using Eigen::Vector3d;

constexpr double kStandardGravity = 9.80665;

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const size_t k = static_cast<size_t>(std::clamp(p, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

template <typename... Args>
std::string format(const char* f, Args... args) {
  char buf[400];
  std::snprintf(buf, sizeof buf, f, args...);
  return buf;
}

// Per-axis mean and variance of samples [b, e).
struct Moments {
  Vector3d mean_w = Vector3d::Zero(), var_w = Vector3d::Zero();
  Vector3d mean_f = Vector3d::Zero(), var_f = Vector3d::Zero();
};
// The rate of the unit specific force over samples [b, e) against the rate the mean gyro reading mean_w would turn it
// at (docs/ins.md eq. 10.2), into the calibration's bias_window_* fields.
void window_rotation(const std::vector<ImuSample>& s, size_t b, size_t e, const Vector3d& mean_w,
                     const CalibrationOptions& o, ImuCalibration& c) {
  const double n = static_cast<double>(e - b);
  if (e - b < 3) return;
  double t_mean = 0.0;
  Vector3d u_mean = Vector3d::Zero();
  for (size_t i = b; i < e; ++i) {
    t_mean += (s[i].t - s[b].t) / n;
    u_mean += s[i].f_ib_b.normalized() / n;
  }
  double stt = 0.0;
  Vector3d stu = Vector3d::Zero();
  for (size_t i = b; i < e; ++i) {
    const double dt = (s[i].t - s[b].t) - t_mean;
    stt += dt * dt;
    stu += dt * (s[i].f_ib_b.normalized() - u_mean);
  }
  if (!(stt > 0.0)) return;
  const Vector3d slope = stu / stt;  // ġ, least squares [1/s]
  double rss = 0.0;
  for (size_t i = b; i < e; ++i) {
    const double dt = (s[i].t - s[b].t) - t_mean;
    rss += (s[i].f_ib_b.normalized() - u_mean - slope * dt).squaredNorm();
  }
  const double sd = std::sqrt(rss / (3.0 * (n - 2.0)) / stt);
  // A direction fixed in the navigation frame seen from sensor axes turning at ω: u̇ = u × ω.
  const Vector3d p = u_mean.normalized().cross(mean_w);
  c.bias_window_tilt_rate_radps = slope.norm();
  c.bias_window_predicted_rate_radps = p.norm();
  c.bias_window_tilt_rate_sd_radps = sd;
  c.bias_window_rotation_k = p.squaredNorm() > 0.0 ? slope.dot(p) / p.squaredNorm() : 0.0;
  c.bias_window_moving = c.bias_window_rotation_k > o.moving_k && p.norm() > o.moving_min_snr * sd;
}

Moments moments(const std::vector<ImuSample>& s, size_t b, size_t e) {
  Moments m;
  const double n = static_cast<double>(e - b);
  for (size_t i = b; i < e; ++i) {
    m.mean_w += s[i].omega_ib_b;
    m.mean_f += s[i].f_ib_b;
  }
  m.mean_w /= n;
  m.mean_f /= n;
  for (size_t i = b; i < e; ++i) {
    m.var_w += (s[i].omega_ib_b - m.mean_w).cwiseAbs2();
    m.var_f += (s[i].f_ib_b - m.mean_f).cwiseAbs2();
  }
  const double dof = std::max(1.0, n - 1.0);
  m.var_w /= dof;
  m.var_f /= dof;
  return m;
}

// The value an axis sits on at its largest magnitude for >= 3 consecutive samples (a clipped sensor), else 0; the
// count of samples at that magnitude.
double plateau(const std::vector<ImuSample>& s, bool gyro, long& count) {
  double best = 0.0;
  count = 0;
  for (int a = 0; a < 3; ++a) {
    double mx = 0.0;
    for (const auto& x : s) mx = std::max(mx, std::abs(gyro ? x.omega_ib_b(a) : x.f_ib_b(a)));
    if (mx <= 0.0) continue;
    long run = 0, at = 0;
    bool is_plateau = false;
    for (const auto& x : s) {
      const double v = std::abs(gyro ? x.omega_ib_b(a) : x.f_ib_b(a));
      if (v >= mx * (1.0 - 1e-9)) {
        ++at;
        if (++run >= 3) is_plateau = true;
      } else {
        run = 0;
      }
    }
    if (is_plateau) {
      best = std::max(best, mx);
      count += at;
    }
  }
  return best;
}

}  // namespace

ImuCalibration calibrate_imu(const std::vector<ImuSample>& s, const CalibrationOptions& o) {
  ImuCalibration c;
  c.samples = s.size();
  if (s.size() < 2) {
    c.warnings.push_back("fewer than 2 samples: nothing can be estimated");
    return c;
  }
  const GpsTime t_first = s.front().t;
  c.duration_s = s.back().t - t_first;

  // Timing: the median interval is the sample period; gaps are excluded from the jitter.
  std::vector<double> dt(s.size() - 1);
  for (size_t i = 1; i < s.size(); ++i) dt[i - 1] = s[i].t - s[i - 1].t;
  c.dt_median_s = percentile(dt, 0.5);
  c.rate_hz = c.dt_median_s > 0.0 ? 1.0 / c.dt_median_s : 0.0;
  double jitter2 = 0.0;
  long n_jitter = 0;
  for (double d : dt) {
    if (d > 1.5 * c.dt_median_s) {
      ++c.gaps;
      continue;
    }
    jitter2 += (d - c.dt_median_s) * (d - c.dt_median_s);
    ++n_jitter;
  }
  c.dt_jitter_s = n_jitter > 0 ? std::sqrt(jitter2 / static_cast<double>(n_jitter)) : 0.0;
  for (size_t i = 1; i < s.size(); ++i) {
    if (s[i].omega_ib_b == s[i - 1].omega_ib_b && s[i].f_ib_b == s[i - 1].f_ib_b) ++c.repeated_samples;
  }

  // Ranges and saturation.
  std::vector<double> w_norm(s.size()), f_norm(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    c.gyro_abs_max_radps = c.gyro_abs_max_radps.cwiseMax(s[i].omega_ib_b.cwiseAbs());
    c.accel_abs_max_mps2 = c.accel_abs_max_mps2.cwiseMax(s[i].f_ib_b.cwiseAbs());
    w_norm[i] = s[i].omega_ib_b.norm();
    f_norm[i] = s[i].f_ib_b.norm();
  }
  c.gyro_p99_radps = percentile(w_norm, 0.99);
  c.accel_p99_mps2 = percentile(f_norm, 0.99);
  c.gyro_plateau_radps = plateau(s, true, c.gyro_saturated_samples);
  c.accel_plateau_mps2 = plateau(s, false, c.accel_saturated_samples);

  // Still windows: variance test against the log's own floor, plus absolute bounds on motion.
  const size_t n_win = std::max<size_t>(4, static_cast<size_t>(std::lround(o.window_s * c.rate_hz)));
  const size_t n_block = std::max<size_t>(1, static_cast<size_t>(std::lround(o.block_s * c.rate_hz)));
  std::vector<Moments> win;
  std::vector<size_t> win_begin;
  std::vector<double> block_w, block_f;  // per window: scatter of its block means (sum over the axes)
  for (size_t b = 0; b + n_win <= s.size(); b += n_win) {
    win.push_back(moments(s, b, b + n_win));
    win_begin.push_back(b);
    std::vector<Vector3d> mw, mf;
    for (size_t k = b; k + n_block <= b + n_win; k += n_block) {
      const Moments m = moments(s, k, k + n_block);
      mw.push_back(m.mean_w);
      mf.push_back(m.mean_f);
    }
    auto scatter = [](const std::vector<Vector3d>& v) {
      if (v.size() < 2) return 0.0;
      Vector3d mean = Vector3d::Zero();
      for (const auto& x : v) mean += x;
      mean /= static_cast<double>(v.size());
      double ss = 0.0;
      for (const auto& x : v) ss += (x - mean).squaredNorm();
      return ss / static_cast<double>(v.size() - 1);
    };
    block_w.push_back(scatter(mw));
    block_f.push_back(scatter(mf));
  }
  std::vector<bool> still(win.size(), false);
  if (!win.empty()) {
    std::vector<double> vw(win.size()), vf(win.size());
    for (size_t k = 0; k < win.size(); ++k) {
      vw[k] = win[k].var_w.sum();
      vf[k] = win[k].var_f.sum();
    }
    c.gyro_var_floor = percentile(vw, o.floor_percentile);
    c.accel_var_floor = percentile(vf, o.floor_percentile);
    for (size_t k = 0; k < win.size(); ++k) {
      // A window of one stalled value has zero variance; the floor then is 0 and only exact repeats pass: such a
      // log is flagged by repeated_samples instead.
      still[k] = vw[k] <= o.still_variance_factor * c.gyro_var_floor &&
                 vf[k] <= o.still_variance_factor * c.accel_var_floor &&
                 std::sqrt(block_w[k]) <= o.max_still_gyro_std_radps &&
                 std::sqrt(block_f[k]) <= o.max_still_accel_std_mps2 &&
                 std::abs(win[k].mean_f.norm() - kStandardGravity) <= o.max_gravity_error_mps2 && vw[k] > 0.0;
    }
  }
  for (size_t k = 0; k < win.size();) {
    if (!still[k]) {
      ++k;
      continue;
    }
    size_t j = k;
    while (j + 1 < win.size() && still[j + 1]) ++j;
    StillPeriod p;
    p.begin = win_begin[k];
    p.end = win_begin[j] + n_win;
    p.t0_s = s[p.begin].t - t_first;
    p.duration_s = s[p.end - 1].t - s[p.begin].t + c.dt_median_s;
    c.still.push_back(p);
    c.still_s += p.duration_s;
    k = j + 1;
  }

  // Noise densities: the variance about each still window's mean, pooled over the still windows.
  Vector3d pooled_w = Vector3d::Zero(), pooled_f = Vector3d::Zero();
  long n_still_win = 0;
  for (size_t k = 0; k < win.size(); ++k) {
    if (!still[k]) continue;
    pooled_w += win[k].var_w;
    pooled_f += win[k].var_f;
    ++n_still_win;
  }
  if (n_still_win > 0 && c.rate_hz > 0.0) {
    c.noise_estimated = true;
    c.gyro_noise_density = (pooled_w / static_cast<double>(n_still_win)).cwiseSqrt() / std::sqrt(c.rate_hz);
    c.accel_noise_density = (pooled_f / static_cast<double>(n_still_win)).cwiseSqrt() / std::sqrt(c.rate_hz);
  }

  // Bias: the first still period of >= min_still_s (where a run starts). Gravity direction: the first still period of
  // any length (one window averages the noise of |f| to well below a degree).
  for (const StillPeriod& p : c.still) {
    if (p.duration_s < o.min_still_s) continue;
    const Moments m = moments(s, p.begin, p.end);
    const double n = static_cast<double>(p.end - p.begin);
    c.bias_estimated = true;
    c.gyro_bias_radps = m.mean_w;
    c.gyro_bias_sd_radps = (m.var_w / n).cwiseSqrt();
    c.bias_window_t0_s = p.t0_s;
    c.bias_window_s = p.duration_s;
    window_rotation(s, p.begin, p.end, m.mean_w, o, c);
    break;
  }
  if (!c.still.empty()) {
    const StillPeriod& p = c.still.front();
    const Moments m = moments(s, p.begin, p.end);
    c.gravity_estimated = true;
    c.gravity_mps2 = m.mean_f.norm();
    c.up_b = m.mean_f / c.gravity_mps2;
    int axis = 0;
    c.up_b.cwiseAbs().maxCoeff(&axis);
    c.up_axis = std::string(c.up_b(axis) >= 0.0 ? "+" : "-") + "xyz"[axis];
    c.tilt_deg = std::acos(std::min(1.0, std::abs(c.up_b(axis)))) * kRadToDeg;
  }

  // Gait: swing peaks of |ω| above swing_rate, at least min_stride_s apart (one per footfall of this foot).
  std::vector<size_t> peaks;
  for (size_t i = 1; i + 1 < s.size(); ++i) {
    if (w_norm[i] < o.swing_rate_radps || w_norm[i] < w_norm[i - 1] || w_norm[i] < w_norm[i + 1]) continue;
    if (!peaks.empty() && s[i].t - s[peaks.back()].t < o.min_stride_s) {
      if (w_norm[i] > w_norm[peaks.back()]) peaks.back() = i;
      continue;
    }
    peaks.push_back(i);
  }
  c.footfalls = static_cast<long>(peaks.size());
  if (peaks.size() >= 2) {
    c.walking_s = s[peaks.back()].t - s[peaks.front()].t;
    c.stride_cadence_per_min = c.walking_s > 0.0 ? 60.0 * static_cast<double>(peaks.size() - 1) / c.walking_s : 0.0;
    long slow = 0;
    for (size_t i = peaks.front(); i <= peaks.back(); ++i) {
      slow += w_norm[i] < o.stance_rate_radps && std::abs(f_norm[i] - kStandardGravity) < 2.0;
    }
    c.stance_share = static_cast<double>(slow) / static_cast<double>(peaks.back() - peaks.front() + 1);
  }

  // What could not be estimated or looks wrong.
  if (!c.bias_estimated) {
    c.warnings.push_back(format(
        "no still period of %.1f s or more (variance test, %.1f s windows): the gyro bias at the start is not "
        "estimated from the log (the auto spec falls back to its floors)",
        o.min_still_s, o.window_s));
  }
  if (c.bias_window_moving) {
    c.warnings.push_back(format(
        "the first still period (%.1f-%.1f s) turns: its mean rate turns gravity in the sensor axes as a motion would "
        "(%.0f deg/h across gravity, measured %.0f deg/h, k %.2f): not a bias (the auto spec keeps its floor)",
        c.bias_window_t0_s, c.bias_window_t0_s + c.bias_window_s,
        c.bias_window_predicted_rate_radps * kRadToDeg * 3600.0, c.bias_window_tilt_rate_radps * kRadToDeg * 3600.0,
        c.bias_window_rotation_k));
  }
  if (c.gravity_estimated && std::abs(c.gravity_mps2 - kStandardGravity) > 0.3) {
    c.warnings.push_back(format("|f| at rest is %.3f m/s^2, not 9.81: check the accelerometer unit and scale",
                                c.gravity_mps2));
  }
  if (c.gravity_estimated && c.tilt_deg > 20.0) {
    c.warnings.push_back(format("up is %.0f deg from the nearest sensor axis: a tilted mounting (levelled at the "
                                "start; fine for the INS, but axis-based settings such as zupt.hmm_gyro_axis "
                                "assume the axes of a flat foot)",
                                c.tilt_deg));
  }
  if (c.footfalls == 0) {
    c.warnings.push_back(format("no swing above %.1f rad/s: no steps in this log (standing, or not a foot-mounted "
                                "IMU): the gait is not estimated",
                                o.swing_rate_radps));
  }
  if (c.rate_hz > 0.0 && c.rate_hz < 80.0) {
    c.warnings.push_back(format("%.0f Hz sample rate: a foot's stance lasts 0.1-0.3 s and its swing reaches 10 rad/s; "
                                "below about 100 Hz stances are a few samples long and the swing is aliased",
                                c.rate_hz));
  }
  if (c.gaps > 0) c.warnings.push_back(format("%.0f gaps longer than 1.5 sample intervals", static_cast<double>(c.gaps)));
  if (c.repeated_samples > static_cast<long>(s.size() / 100)) {
    c.warnings.push_back(format("%.0f samples repeat the previous one exactly (%.1f %%): a stalled or duplicated logger",
                                static_cast<double>(c.repeated_samples),
                                100.0 * static_cast<double>(c.repeated_samples) / static_cast<double>(s.size())));
  }
  if (c.gyro_plateau_radps > 0.0) {
    c.warnings.push_back(format("gyro saturated at %.2f rad/s (%.0f samples on the plateau)", c.gyro_plateau_radps,
                                static_cast<double>(c.gyro_saturated_samples)));
  }
  if (c.accel_plateau_mps2 > 0.0) {
    c.warnings.push_back(format("accelerometer saturated at %.1f m/s^2 (%.0f samples on the plateau)",
                                c.accel_plateau_mps2, static_cast<double>(c.accel_saturated_samples)));
  }
  return c;
}

}  // namespace pednav::ins

namespace pednav::ins {

ImuSpec spec_from_calibration(const ImuCalibration& c, const AutoSpecOptions& o) {
  ImuSpec s;
  s.name = "auto";
  const double arw = c.noise_estimated ? c.gyro_noise_density.maxCoeff() : 0.0;
  const double vrw = c.noise_estimated ? c.accel_noise_density.maxCoeff() : 0.0;
  s.gyro_arw = std::max(arw, o.gyro_noise_floor);
  s.accel_vrw = std::max(vrw, o.accel_noise_floor);
  const bool window_is_bias = c.bias_estimated && !c.bias_window_moving;  // eq. 10.2
  s.gyro_bias_initial = std::max(window_is_bias ? c.gyro_bias_radps.cwiseAbs().maxCoeff() : 0.0,
                                 o.gyro_bias_initial_floor);
  s.gyro_bias_instability = o.gyro_bias_instability;
  s.gyro_bias_tau_s = o.gyro_bias_tau_s;
  s.accel_bias_initial = o.accel_bias_initial;
  s.accel_bias_instability = o.accel_bias_instability;
  s.accel_bias_tau_s = o.accel_bias_tau_s;
  s.gyro_range = c.gyro_plateau_radps;
  s.accel_range = c.accel_plateau_mps2;
  return s;
}

AutoThreshold auto_shoe_threshold(const std::vector<double>& t, const ImuCalibration& c,
                                  const AutoThresholdOptions& o) {
  AutoThreshold a;
  std::vector<double> at_rest;
  for (const StillPeriod& p : c.still) {
    for (size_t i = p.begin; i < p.end && i < t.size(); ++i) at_rest.push_back(t[i]);
  }
  a.from_still = !at_rest.empty();
  a.rest = a.from_still ? percentile(at_rest, o.rest_quantile) : percentile(t, 0.05);
  a.threshold = a.rest + o.motion;
  a.cap = o.two_class_cap;
  if (o.two_class_cap > 0.0) {  // docs/zupt.md eq. 6.2
    a.split = two_class_split(t);
    const double capped = std::min(a.split, o.two_class_cap);
    if (capped > a.threshold) {
      a.threshold = capped;
      a.from_split = true;
    }
  }
  return a;
}

double two_class_split(const std::vector<double>& t, int bins) {
  if (t.empty() || bins < 2) return 0.0;
  std::vector<double> lt(t.size());
  double lo = 1e300, hi = -1e300;
  for (size_t i = 0; i < t.size(); ++i) {
    lt[i] = std::log10(std::max(t[i], 1e-6));
    lo = std::min(lo, lt[i]);
    hi = std::max(hi, lt[i]);
  }
  if (!(hi > lo)) return 0.0;
  std::vector<double> h(static_cast<size_t>(bins), 0.0);
  const double w = (hi - lo) / bins;
  for (double v : lt) h[static_cast<size_t>(std::min(bins - 1, static_cast<int>((v - lo) / w)))] += 1.0;
  // Between-class variance of the bin index for a split after bin i: w_b w_f (μ_b − μ_f)² (up to a constant).
  const double n = static_cast<double>(lt.size());
  double total = 0.0;
  for (int i = 0; i < bins; ++i) total += i * h[static_cast<size_t>(i)];
  double wb = 0.0, sb = 0.0, best = -1.0;
  int best_i = 0;
  for (int i = 0; i < bins; ++i) {
    wb += h[static_cast<size_t>(i)];
    if (wb == 0.0 || wb == n) continue;
    sb += i * h[static_cast<size_t>(i)];
    const double mb = sb / wb, mf = (total - sb) / (n - wb);
    const double var = wb * (n - wb) * (mb - mf) * (mb - mf);
    if (var > best) {
      best = var;
      best_i = i;
    }
  }
  return std::pow(10.0, lo + (best_i + 1) * w);
}

}  // namespace pednav::ins
