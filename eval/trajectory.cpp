// SPDX-License-Identifier: BSD-2-Clause
#include "eval/trajectory.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"

namespace pednav::eval {
namespace {

// Reference position at time t: the nearest epoch within the tolerance, else linear interpolation between the
// bracketing epochs if they are at most max_gap apart. Returns false if neither applies.
bool reference_at(const Trajectory& ref, GpsTime t, const CompareOptions& o, Eigen::Vector3d& p) {
  const auto& pts = ref.points;
  auto it = std::lower_bound(pts.begin(), pts.end(), t, [](const TrajectoryPoint& a, GpsTime b) { return a.t < b; });
  const TrajectoryPoint* after = (it != pts.end()) ? &*it : nullptr;
  const TrajectoryPoint* before = (it != pts.begin()) ? &*(it - 1) : nullptr;
  const double d_after = after ? std::abs(after->t - t) : 1e300;
  const double d_before = before ? std::abs(t - before->t) : 1e300;
  if (std::min(d_after, d_before) <= o.time_tolerance_s) {
    p = (d_after < d_before) ? after->p : before->p;
    return true;
  }
  if (before && after && (after->t - before->t) <= o.max_interp_gap_s) {
    const double w = (t - before->t) / (after->t - before->t);
    p = (1.0 - w) * before->p + w * after->p;
    return true;
  }
  return false;
}

// Least-squares rigid transform dst ~= R src + t (Umeyama 1991 without scale); yaw_only restricts R to a rotation
// about the vertical (ENU z).
void fit_rigid(const std::vector<Eigen::Vector3d>& src, const std::vector<Eigen::Vector3d>& dst, bool yaw_only,
               Eigen::Matrix3d& R, Eigen::Vector3d& t) {
  Eigen::Vector3d ms = Eigen::Vector3d::Zero(), md = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < src.size(); ++i) {
    ms += src[i];
    md += dst[i];
  }
  ms /= static_cast<double>(src.size());
  md /= static_cast<double>(src.size());
  if (yaw_only) {
    double sxx = 0.0, sxy = 0.0;  // maximize sum (dst_h . R src_h)
    for (size_t i = 0; i < src.size(); ++i) {
      const Eigen::Vector3d a = src[i] - ms, b = dst[i] - md;
      sxx += a.x() * b.x() + a.y() * b.y();
      sxy += a.x() * b.y() - a.y() * b.x();
    }
    const double yaw = std::atan2(sxy, sxx);
    R = Eigen::Matrix3d::Identity();
    R(0, 0) = std::cos(yaw);
    R(0, 1) = -std::sin(yaw);
    R(1, 0) = std::sin(yaw);
    R(1, 1) = std::cos(yaw);
  } else {
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < src.size(); ++i) cov += (dst[i] - md) * (src[i] - ms).transpose();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
    if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) s(2, 2) = -1.0;
    R = svd.matrixU() * s * svd.matrixV().transpose();
  }
  t = md - R * ms;
}

}  // namespace

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

double path_length_horizontal_m(const Trajectory& tr) {
  if (tr.points.size() < 2) return 0.0;
  const Eigen::Vector3d origin = tr.points.front().p;
  double d = 0.0;
  Eigen::Vector3d prev = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < tr.points.size(); ++i) {
    const Eigen::Vector3d enu =
        tr.frame == Frame::kEcef ? enu_from_ecef(tr.points[i].p, origin) : Eigen::Vector3d(tr.points[i].p - origin);
    if (i > 0) d += (enu - prev).head<2>().norm();
    prev = enu;
  }
  return d;
}

Expected<Evaluation> compare(const Trajectory& sol, const Trajectory& ref, const CompareOptions& o) {
  if (sol.points.empty()) return make_error("solution: no epochs");
  if (ref.points.empty()) return make_error("reference: no epochs");
  if (ref.frame == Frame::kLocalEnu && o.align == Align::kNone) {
    return make_error("reference is in a local frame: choose --align start, best-fit-2d or best-fit-3d");
  }
  // Work in ENU about an origin: the first reference point (ECEF) or the local frame as is.
  const bool ecef_ref = ref.frame == Frame::kEcef;
  const Eigen::Vector3d origin_e = ecef_ref ? ref.points.front().p : Eigen::Vector3d::Zero();
  const Eigen::Vector3d sol_origin_e = sol.points.front().p;
  auto sol_enu = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    if (sol.frame == Frame::kLocalEnu) return p;
    return enu_from_ecef(p, ecef_ref ? origin_e : sol_origin_e);
  };
  auto ref_enu = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    return ecef_ref ? enu_from_ecef(p, origin_e) : p;
  };

  std::vector<GpsTime> times;
  std::vector<Eigen::Vector3d> s_enu, r_enu, s_sd;
  for (const auto& sp : sol.points) {
    Eigen::Vector3d rp;
    if (!reference_at(ref, sp.t, o, rp)) continue;
    times.push_back(sp.t);
    s_sd.push_back(sp.sd_enu_m);
    s_enu.push_back(sol_enu(sp.p));
    r_enu.push_back(ref_enu(rp));
  }
  if (times.empty()) {
    return make_error("no overlapping epochs: solution " + sol.points.front().t.to_string() + " .. " +
                      sol.points.back().t.to_string() + ", reference " + ref.points.front().t.to_string() + " .. " +
                      ref.points.back().t.to_string());
  }

  Evaluation ev;
  if (o.align == Align::kStart || o.align == Align::kStartPyshoe) {
    // Translate to the common start; rotate about the vertical so that the direction to the first reference point
    // >= 1 m from the start agrees (kStartPyshoe: the first solution epoch >= 0.8 m from the solution's start,
    // else the epoch 1.5 s after the start).
    size_t k = 1;
    if (o.align == Align::kStart) {
      while (k < r_enu.size() && (r_enu[k] - r_enu[0]).head<2>().norm() < 1.0) ++k;
    } else {
      while (k < s_enu.size() && (s_enu[k] - s_enu[0]).head<2>().norm() < 0.8) ++k;
      if (k == s_enu.size()) {
        k = 1;
        while (k < times.size() && times[k] - times[0] < 1.5) ++k;
      }
    }
    double yaw = 0.0;
    if (k < r_enu.size()) {
      const Eigen::Vector3d dr = r_enu[k] - r_enu[0], ds = s_enu[k] - s_enu[0];
      yaw = std::atan2(dr.y(), dr.x()) - std::atan2(ds.y(), ds.x());
    }
    ev.R_align = Eigen::Matrix3d::Identity();
    ev.R_align.topLeftCorner<2, 2>() << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
    ev.t_align = r_enu[0] - ev.R_align * s_enu[0];
  } else if (o.align == Align::kBestFit2d || o.align == Align::kBestFit3d) {
    if (s_enu.size() < 3) return make_error("alignment needs at least 3 matched epochs");
    fit_rigid(s_enu, r_enu, o.align == Align::kBestFit2d, ev.R_align, ev.t_align);
  }

  std::vector<double> horiz, vert;
  int bins[4] = {0, 0, 0, 0};
  double sum_h2 = 0, sum_h = 0, sum_v2 = 0, sum_v = 0;
  for (size_t i = 0; i < times.size(); ++i) {
    const Eigen::Vector3d d = ev.R_align * s_enu[i] + ev.t_align - r_enu[i];
    const double h = d.head<2>().norm();
    ev.errors.push_back({times[i], d, h, s_sd[i]});
    horiz.push_back(h);
    vert.push_back(d.z());
    sum_h += h;
    sum_h2 += h * h;
    sum_v += d.z();
    sum_v2 += d.z() * d.z();
    ev.vertical_max_abs_m = std::max(ev.vertical_max_abs_m, std::abs(d.z()));
    bins[h < 5.0 ? 0 : h < 10.0 ? 1 : h < 20.0 ? 2 : 3]++;
  }
  const double n = static_cast<double>(times.size());
  ev.epochs_compared = static_cast<int>(times.size());
  // Availability: share of reference epochs inside the solution's span that have a solution epoch within
  // max(tolerance, half the solution's median interval), so a 10 Hz reference does not penalize a 1 Hz solution.
  std::vector<double> dts;
  for (size_t i = 1; i < sol.points.size(); ++i) dts.push_back(sol.points[i].t - sol.points[i - 1].t);
  const double window_s = std::max(o.time_tolerance_s, dts.empty() ? 0.0 : 0.5 * quantile(dts, 0.5) + 1e-6);
  const GpsTime t0 = sol.points.front().t.plus_s(-window_s);
  const GpsTime t1 = sol.points.back().t.plus_s(window_s);
  int available = 0;
  for (const auto& rp : ref.points) {
    if (rp.t < t0 || rp.t > t1) continue;
    ++ev.reference_epochs;
    auto it = std::lower_bound(sol.points.begin(), sol.points.end(), rp.t,
                               [](const TrajectoryPoint& a, GpsTime b) { return a.t < b; });
    const bool near_after = it != sol.points.end() && std::abs(it->t - rp.t) <= window_s;
    const bool near_before = it != sol.points.begin() && std::abs((it - 1)->t - rp.t) <= window_s;
    if (near_after || near_before) ++available;
  }
  ev.availability_pct = ev.reference_epochs > 0 ? 100.0 * available / ev.reference_epochs : 0.0;
  ev.horizontal_rms_m = std::sqrt(sum_h2 / n);
  ev.horizontal_mean_m = sum_h / n;
  ev.horizontal_p50_m = quantile(horiz, 0.5);
  ev.horizontal_p95_m = quantile(horiz, 0.95);
  ev.horizontal_max_m = *std::max_element(horiz.begin(), horiz.end());
  ev.vertical_rms_m = std::sqrt(sum_v2 / n);
  ev.vertical_mean_m = sum_v / n;
  for (int b = 0; b < 4; ++b) ev.bins_pct[b] = 100.0 * bins[b] / n;

  if (o.loop) {
    ev.has_closure = true;
    const Eigen::Vector3d a = sol_enu(sol.points.front().p), b = sol_enu(sol.points.back().p);
    ev.closure_m = (b - a).head<2>().norm();
    ev.distance_m = path_length_horizontal_m(sol);
    ev.closure_pct_of_distance = ev.distance_m > 0.0 ? 100.0 * ev.closure_m / ev.distance_m : 0.0;
  }
  return ev;
}

}  // namespace pednav::eval
