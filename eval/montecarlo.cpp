// SPDX-License-Identifier: BSD-2-Clause
#include "eval/montecarlo.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <map>

namespace pednav::eval {
namespace {

// Running sums of one epoch across runs.
struct Acc {
  int n = 0;
  double dist = 0.0;
  Eigen::Vector3d sum_e = Eigen::Vector3d::Zero(), sum_e2 = Eigen::Vector3d::Zero(), sum_var = Eigen::Vector3d::Zero();
  double sum_y = 0.0, sum_y2 = 0.0, sum_vy = 0.0;
  double sum_h2 = 0.0, nees_h = 0.0, nees_y = 0.0;
  int inside3 = 0;
};

// The epoch's average horizontal NEES is inside its two-sided 95 % band.
bool nees_in_band(const McEpochStats& e) { return e.nees_horizontal >= e.nees_lo_2dof && e.nees_horizontal <= e.nees_hi_2dof; }

}  // namespace

double normal_quantile(double p) {
  if (!(p > 0.0 && p < 1.0)) return std::nan("");
  // Φ(x) = erfc(−x/√2)/2, Φ'(x) = exp(−x²/2)/√(2π); Newton from x = 0 converges for the p used here
  // (|x| < 8); a bisection bracket guards the steps.
  double lo = -40.0, hi = 40.0, x = 0.0;
  for (int i = 0; i < 100; ++i) {
    const double f = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
    if (f > 0) hi = x; else lo = x;
    const double d = std::exp(-0.5 * x * x) / std::sqrt(2.0 * M_PI);
    double xn = d > 1e-300 ? x - f / d : 0.5 * (lo + hi);
    if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
    if (std::abs(xn - x) < 1e-14) return xn;
    x = xn;
  }
  return x;
}

double chi_square_quantile_wh(double p, double dof) {
  // Wilson & Hilferty (1931): (χ²/k)^(1/3) ≈ N(1 − 2/(9k), 2/(9k)).
  const double a = 2.0 / (9.0 * dof);
  const double c = 1.0 - a + normal_quantile(p) * std::sqrt(a);
  return dof * c * c * c;
}

std::pair<double, double> average_nees_band(int runs, int dof, double prob) {
  const double k = static_cast<double>(runs) * dof;
  return {chi_square_quantile_wh(0.5 * (1.0 - prob), k) / runs, chi_square_quantile_wh(0.5 * (1.0 + prob), k) / runs};
}

std::vector<McEpochStats> aggregate_epochs(const std::vector<McRun>& runs, bool smoothed, int min_runs,
                                           double key_resolution_s) {
  std::map<long long, Acc> acc;
  std::map<long long, double> key_t;
  for (const McRun& r : runs) {
    for (const McEpoch& e : smoothed ? r.smoothed : r.forward) {
      const long long key = std::llround(e.t_s / key_resolution_s);
      Acc& a = acc[key];
      key_t[key] = e.t_s;
      ++a.n;
      a.dist += e.distance_m;
      a.sum_e += e.err_ned_m;
      a.sum_e2 += e.err_ned_m.cwiseAbs2();
      a.sum_var += e.cov_ned_m2.diagonal();
      a.sum_y += e.err_yaw_rad;
      a.sum_y2 += e.err_yaw_rad * e.err_yaw_rad;
      a.sum_vy += e.var_yaw_rad2;
      const Eigen::Vector2d eh = e.err_ned_m.head<2>();
      a.sum_h2 += eh.squaredNorm();
      // NEES of the horizontal error: e_hᵀ P_h⁻¹ e_h (P_h the N-E block, with its correlation).
      const Eigen::Matrix2d Ph = e.cov_ned_m2.topLeftCorner<2, 2>();
      a.nees_h += eh.dot(Ph.ldlt().solve(eh));
      a.nees_y += e.var_yaw_rad2 > 0 ? e.err_yaw_rad * e.err_yaw_rad / e.var_yaw_rad2 : 0.0;
      a.inside3 += std::abs(eh.x()) <= 3.0 * std::sqrt(Ph(0, 0)) && std::abs(eh.y()) <= 3.0 * std::sqrt(Ph(1, 1));
    }
  }
  std::vector<McEpochStats> out;
  const int min_n = std::max(2, min_runs);
  for (const auto& [key, a] : acc) {
    if (a.n < min_n) continue;
    McEpochStats s;
    const double n = a.n;
    s.t_s = key_t[key];
    s.runs = a.n;
    s.distance_m = a.dist / n;
    s.mean_err_ned_m = a.sum_e / n;
    // Sample variance with the (M − 1) denominator (seed 000, σ̄_E(k)).
    const Eigen::Vector3d var = ((a.sum_e2 - n * s.mean_err_ned_m.cwiseAbs2()) / (n - 1.0)).cwiseMax(0.0);
    s.sample_sd_ned_m = var.cwiseSqrt();
    s.filter_sd_ned_m = (a.sum_var / n).cwiseSqrt();
    s.mean_err_yaw_rad = a.sum_y / n;
    s.sample_sd_yaw_rad = std::sqrt(std::max(0.0, (a.sum_y2 - n * s.mean_err_yaw_rad * s.mean_err_yaw_rad) / (n - 1.0)));
    s.filter_sd_yaw_rad = std::sqrt(a.sum_vy / n);
    s.rms_horizontal_m = std::sqrt(a.sum_h2 / n);
    s.nees_horizontal = a.nees_h / n;
    s.nees_yaw = a.nees_y / n;
    std::tie(s.nees_lo_2dof, s.nees_hi_2dof) = average_nees_band(a.n, 2);
    std::tie(s.nees_lo_1dof, s.nees_hi_1dof) = average_nees_band(a.n, 1);
    s.inside_3sigma_fraction = a.inside3 / n;
    out.push_back(s);
  }
  return out;
}

McSummary summarize(const std::vector<McEpochStats>& epochs, int runs, double t_from_s) {
  McSummary m;
  m.runs = runs;
  double in_h = 0, in_y = 0, above = 0, below = 0, nees = 0, sv = 0, fv = 0, svy = 0, fvy = 0, in3 = 0, h2 = 0, w = 0;
  std::vector<double> ratio_h, ratio_y;
  for (const McEpochStats& e : epochs) {
    if (e.t_s < t_from_s) continue;
    ++m.epochs;
    const double fh = e.filter_sd_ned_m.head<2>().norm();
    if (fh > 0) ratio_h.push_back(e.sample_sd_ned_m.head<2>().norm() / fh);
    if (e.filter_sd_yaw_rad > 0) ratio_y.push_back(e.sample_sd_yaw_rad / e.filter_sd_yaw_rad);
    in_h += nees_in_band(e);
    above += e.nees_horizontal > e.nees_hi_2dof;
    below += e.nees_horizontal < e.nees_lo_2dof;
    in_y += e.nees_yaw >= e.nees_lo_1dof && e.nees_yaw <= e.nees_hi_1dof;
    nees += e.nees_horizontal;
    sv += e.sample_sd_ned_m.head<2>().squaredNorm();
    fv += e.filter_sd_ned_m.head<2>().squaredNorm();
    svy += e.sample_sd_yaw_rad * e.sample_sd_yaw_rad;
    fvy += e.filter_sd_yaw_rad * e.filter_sd_yaw_rad;
    in3 += e.inside_3sigma_fraction * e.runs;
    h2 += e.rms_horizontal_m * e.rms_horizontal_m * e.runs;
    w += e.runs;
  }
  if (m.epochs == 0) return m;
  const double k = m.epochs;
  m.nees_in_band_fraction = in_h / k;
  m.nees_yaw_in_band_fraction = in_y / k;
  m.nees_above_band_fraction = above / k;
  m.nees_below_band_fraction = below / k;
  m.mean_nees_horizontal = nees / k;
  m.sigma_ratio_horizontal_pooled = fv > 0 ? std::sqrt(sv / fv) : 0.0;
  m.sigma_ratio_yaw_pooled = fvy > 0 ? std::sqrt(svy / fvy) : 0.0;
  auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  m.sigma_ratio_horizontal = median(ratio_h);
  m.sigma_ratio_yaw = median(ratio_y);
  m.inside_3sigma_fraction = in3 / w;
  m.rms_horizontal_m = std::sqrt(h2 / w);
  return m;
}

std::vector<McWindowBand> window_bands(const std::vector<McEpochStats>& epochs, double window_s) {
  std::vector<McWindowBand> out;
  if (!(window_s > 0.0)) return out;
  for (const McEpochStats& e : epochs) {
    const double from = std::floor(std::max(0.0, e.t_s) / window_s) * window_s;
    if (out.empty() || out.back().from_s != from) out.push_back({from, from + window_s, 0, 0.0, 0.0});
    McWindowBand& w = out.back();
    ++w.epochs;
    w.nees_in_band_fraction += nees_in_band(e);
    w.mean_nees_horizontal += e.nees_horizontal;
  }
  for (McWindowBand& w : out) {
    w.nees_in_band_fraction /= w.epochs;
    w.mean_nees_horizontal /= w.epochs;
  }
  return out;
}

McCarrierSummary summarize_carrier(const std::vector<McRun>& runs) {
  McCarrierSummary s;
  s.runs = static_cast<int>(runs.size());
  double nees = 0.0;
  std::vector<double> ttff;
  for (const McRun& r : runs) {
    const McCarrierRun& c = r.carrier;
    s.gnss_epochs += c.gnss_epochs;
    s.fixed_epochs += c.fixed_epochs;
    s.wrong_fixed_epochs += c.wrong_fixed_epochs;
    s.runs_with_fix += c.fixed_epochs > 0;
    s.runs_with_wrong_fix += c.wrong_fixed_epochs > 0;
    nees += c.antenna_nees_sum;
    if (c.fixed_epochs > 0 && c.time_to_first_fix_s >= 0.0) ttff.push_back(c.time_to_first_fix_s);
  }
  if (s.gnss_epochs > 0) s.fix_rate = static_cast<double>(s.fixed_epochs) / static_cast<double>(s.gnss_epochs);
  if (s.fixed_epochs > 0) {
    s.wrong_fix_rate = static_cast<double>(s.wrong_fixed_epochs) / static_cast<double>(s.fixed_epochs);
    s.mean_antenna_nees_fixed = nees / static_cast<double>(s.fixed_epochs);
  }
  if (!ttff.empty()) {
    std::sort(ttff.begin(), ttff.end());
    const size_t n = ttff.size();
    s.median_time_to_first_fix_s = n % 2 ? ttff[n / 2] : 0.5 * (ttff[n / 2 - 1] + ttff[n / 2]);
    s.max_time_to_first_fix_s = ttff.back();
  }
  return s;
}

}  // namespace pednav::eval
