// SPDX-License-Identifier: BSD-2-Clause
#include "eval/statistics.hpp"

#include <algorithm>
#include <cmath>

namespace pednav::eval {

std::vector<SegmentStats> segment_statistics(const std::vector<EpochError>& errors, double segment_s) {
  std::vector<SegmentStats> out;
  if (errors.empty() || !(segment_s > 0.0)) return out;
  const GpsTime t0 = errors.front().t;
  long current = -1;
  double sum_h2 = 0.0, sum_v2 = 0.0, sum_e = 0.0, sum_n = 0.0;
  auto close = [&] {
    if (out.empty() || out.back().epochs == 0) return;
    SegmentStats& s = out.back();
    s.horizontal_rms_m = std::sqrt(sum_h2 / s.epochs);
    s.vertical_rms_m = std::sqrt(sum_v2 / s.epochs);
    s.horizontal_mean_e_m = sum_e / s.epochs;
    s.horizontal_mean_n_m = sum_n / s.epochs;
  };
  for (const EpochError& e : errors) {
    const long k = static_cast<long>(std::floor((e.t - t0) / segment_s));
    if (k != current) {
      close();
      out.push_back({});
      out.back().t_start = e.t;
      sum_h2 = sum_v2 = sum_e = sum_n = 0.0;
      current = k;
    }
    SegmentStats& s = out.back();
    s.t_end = e.t;
    ++s.epochs;
    s.horizontal_max_m = std::max(s.horizontal_max_m, e.horizontal_m);
    sum_h2 += e.horizontal_m * e.horizontal_m;
    sum_v2 += e.d_enu.z() * e.d_enu.z();
    sum_e += e.d_enu.x();
    sum_n += e.d_enu.y();
  }
  close();
  return out;
}

VerticalStats vertical_statistics(const std::vector<EpochError>& errors) {
  VerticalStats v;
  if (errors.empty()) return v;
  const double n = static_cast<double>(errors.size());
  double sum = 0.0, sum2 = 0.0;
  std::vector<double> abs_up;
  for (const auto& e : errors) {
    sum += e.d_enu.z();
    sum2 += e.d_enu.z() * e.d_enu.z();
    abs_up.push_back(std::abs(e.d_enu.z()));
    v.max_abs_m = std::max(v.max_abs_m, std::abs(e.d_enu.z()));
  }
  v.mean_m = sum / n;
  v.rms_m = std::sqrt(sum2 / n);
  v.std_m = std::sqrt(std::max(0.0, sum2 / n - v.mean_m * v.mean_m));
  v.p95_abs_m = quantile(abs_up, 0.95);
  return v;
}

ConsistencyStats consistency_statistics(const std::vector<EpochError>& errors) {
  ConsistencyStats c;
  long inside = 0, inside_v = 0, n_v = 0;
  double sum_q = 0.0;
  for (const auto& e : errors) {
    const double se = e.sd_enu_m.x(), sn = e.sd_enu_m.y(), su = e.sd_enu_m.z();
    if (!(std::isfinite(se) && std::isfinite(sn) && se > 0.0 && sn > 0.0)) continue;
    const double qe = e.d_enu.x() / se, qn = e.d_enu.y() / sn;
    ++c.epochs;
    inside += std::abs(qe) <= 3.0 && std::abs(qn) <= 3.0;
    sum_q += qe * qe + qn * qn;
    c.max_normalized_horizontal = std::max({c.max_normalized_horizontal, std::abs(qe), std::abs(qn)});
    if (std::isfinite(su) && su > 0.0) {
      ++n_v;
      inside_v += std::abs(e.d_enu.z() / su) <= 3.0;
    }
  }
  if (c.epochs == 0) return c;
  c.inside_3sigma_pct = 100.0 * static_cast<double>(inside) / c.epochs;
  c.mean_normalized_sq_horizontal = sum_q / c.epochs;
  if (n_v > 0) c.inside_3sigma_vertical_pct = 100.0 * static_cast<double>(inside_v) / static_cast<double>(n_v);
  return c;
}

}  // namespace pednav::eval
