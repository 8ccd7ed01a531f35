#include "ins/zupt_detector.hpp"

#include <algorithm>
#include <cmath>

namespace pednav::ins {
namespace {

// Half window in samples for a window of `window_s` at the median sample step.
int half_window(const std::vector<ImuSample>& s, double window_s) {
  if (s.size() < 2) return 0;
  const double dt = (s.back().t - s.front().t) / static_cast<double>(s.size() - 1);
  return std::max(1, static_cast<int>(std::lround(0.5 * window_s / std::max(dt, 1e-6))));
}

void drop_short_runs(std::vector<ZuptDecision>& d, const std::vector<ImuSample>& s, double min_s) {
  size_t i = 0;
  while (i < d.size()) {
    if (!d[i].stance) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < d.size() && d[j + 1].stance) ++j;
    if (s[j].t - s[i].t < min_s) {
      for (size_t k = i; k <= j; ++k) d[k].stance = false;
    }
    i = j + 1;
  }
}

}  // namespace

std::vector<std::string> ZuptDetectorOptions::problems() const {
  std::vector<std::string> p;
  if (detector != "mv" && detector != "shoe") p.push_back("zupt.detector '" + detector + "' is not mv or shoe");
  if (mv_window_s <= 0) p.push_back("zupt.mv_window_s must be > 0");
  if (mv_threshold_mps2 <= 0) p.push_back("zupt.mv_threshold_mps2 must be > 0");
  if (shoe_window_s <= 0) p.push_back("zupt.shoe_window_s must be > 0");
  if (shoe_threshold <= 0) p.push_back("zupt.shoe_threshold must be > 0");
  if (shoe_sigma_accel_mps2 <= 0 || shoe_sigma_gyro_radps <= 0) p.push_back("zupt.shoe sigmas must be > 0");
  if (min_time_since_step_s < 0) p.push_back("zupt.min_time_since_step_s must be >= 0");
  return p;
}

std::vector<ZuptDecision> detect_stance(const std::vector<ImuSample>& s, const ZuptDetectorOptions& o) {
  const int n = static_cast<int>(s.size());
  std::vector<ZuptDecision> d(n);
  if (n == 0) return d;
  if (o.detector == "shoe") {
    const int h = half_window(s, o.shoe_window_s);
    const double ia = 1.0 / (o.shoe_sigma_accel_mps2 * o.shoe_sigma_accel_mps2);
    const double ig = 1.0 / (o.shoe_sigma_gyro_radps * o.shoe_sigma_gyro_radps);
    for (int k = 0; k < n; ++k) {
      const int a = std::max(0, k - h), b = std::min(n - 1, k + h);
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (int j = a; j <= b; ++j) mean += s[j].f_ib_b;
      mean /= static_cast<double>(b - a + 1);
      const Eigen::Vector3d g_dir = mean.norm() > 0 ? Eigen::Vector3d(mean.normalized() * 9.80665) : Eigen::Vector3d::Zero();
      double t = 0.0;
      for (int j = a; j <= b; ++j) t += ia * (s[j].f_ib_b - g_dir).squaredNorm() + ig * s[j].omega_ib_b.squaredNorm();
      d[k].statistic = t / static_cast<double>(b - a + 1);
      d[k].stance = d[k].statistic < o.shoe_threshold;
    }
  } else {
    // seed 004 eq. 1: sigma_{k} = std of |f| over the window; stance if sigma < threshold and t_k - t_s > Δt,
    // t_s = start of the current step (the last sample that was moving after a stance).
    const int h = half_window(s, o.mv_window_s);
    std::vector<double> mag(n);
    for (int k = 0; k < n; ++k) mag[k] = s[k].f_ib_b.norm();
    bool moving = true;
    GpsTime step_start = s.front().t.plus_s(-1e3);  // the log may start still
    for (int k = 0; k < n; ++k) {
      const int a = std::max(0, k - h), b = std::min(n - 1, k + h);
      double m = 0.0, m2 = 0.0;
      for (int j = a; j <= b; ++j) {
        m += mag[j];
        m2 += mag[j] * mag[j];
      }
      const double cnt = static_cast<double>(b - a + 1);
      const double var = std::max(0.0, m2 / cnt - (m / cnt) * (m / cnt));
      d[k].statistic = std::sqrt(var);
      const bool quiet = d[k].statistic < o.mv_threshold_mps2 &&
                         (o.mv_gyro_threshold_radps <= 0 || s[k].omega_ib_b.norm() < o.mv_gyro_threshold_radps);
      if (!quiet) {
        if (!moving) step_start = s[k].t;  // a new step begins
        moving = true;
        d[k].stance = false;
      } else {
        d[k].stance = (s[k].t - step_start) > o.min_time_since_step_s;
        if (d[k].stance) moving = false;
      }
    }
  }
  drop_short_runs(d, s, o.min_stance_s);
  return d;
}

}  // namespace pednav::ins
