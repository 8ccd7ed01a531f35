// SPDX-License-Identifier: BSD-2-Clause
// Initialization of the engine's state (fusion/initialization.hpp).
#include "fusion/initialization.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/forward_runner.hpp"
#include "gnss/least_squares.hpp"

namespace pednav::fusion {
namespace {

using Eigen::Vector3d;

// The first still period's mean rate is taken as the initial gyro bias when its d² (docs/ins.md eq. 6.1) is within
// the χ²(3) quantile at this probability.
constexpr double kStillGyroBiasGateProbability = 0.999;

// printf-style message (the engine's texts; fusion/ has no logging or fmt dependency).
template <typename... Args>
std::string fmt_message(const char* format, Args... args) {
  char buf[400];
  std::snprintf(buf, sizeof buf, format, args...);
  return buf;
}

std::pair<double, double> fit_yaw(const std::vector<Vector3d>& src, const std::vector<Vector3d>& dst) {
  Vector3d ms = Vector3d::Zero(), md = Vector3d::Zero();
  for (size_t i = 0; i < src.size(); ++i) ms += src[i], md += dst[i];
  ms /= static_cast<double>(src.size());
  md /= static_cast<double>(src.size());
  double sxx = 0, sxy = 0;
  for (size_t i = 0; i < src.size(); ++i) {
    const Vector3d a = src[i] - ms, b = dst[i] - md;
    sxx += a.x() * b.x() + a.y() * b.y();
    sxy += a.x() * b.y() - a.y() * b.x();
  }
  const double th = std::atan2(sxy, sxx);
  const double c = std::cos(th), s = std::sin(th);
  double ss = 0;
  for (size_t i = 0; i < src.size(); ++i) {
    const Vector3d a = src[i] - ms, b = dst[i] - md;
    const double ex = c * a.x() - s * a.y() - b.x(), ey = s * a.x() + c * a.y() - b.y();
    ss += ex * ex + ey * ey;
  }
  return {th, std::sqrt(ss / static_cast<double>(src.size()))};
}

}  // namespace

std::optional<std::pair<size_t, size_t>> first_still_period(const std::vector<ins::ImuSample>& samples,
                                                            const std::vector<ins::ZuptDecision>& decisions) {
  for (size_t i = 0; i < decisions.size(); ++i) {
    if (!decisions[i].stance) continue;
    size_t j = i;
    while (j + 1 < decisions.size() && decisions[j + 1].stance) ++j;
    if (samples[j].t - samples[i].t >= kMinLevellingWindowS) return std::make_pair(i, j + 1);
    i = j;
  }
  return std::nullopt;
}

ins::ImuErrors initial_imu_errors(const ins::Levelling& level, const ins::ImuSpec& spec, EngineSummary& sum,
                                  std::string& how) {
  ins::ImuErrors imu0;
  // The still period's mean rate as the initial gyro bias — unless the window moved (docs/ins.md §6, eq. 6.1).
  if (level.duration_s >= kMinBiasWindowS) {
    const Vector3d b_deg_per_h = level.gyro_bias_b * kRadToDeg * 3600.0;
    // A spec without a turn-on σ has no prior to check against: the window's mean is taken (d² stays 0).
    if (spec.gyro_bias_initial > 0.0)
      sum.still_gyro_bias_d2 = ins::still_gyro_bias_d2(level, spec.gyro_bias_initial, spec.gyro_arw);
    if (sum.still_gyro_bias_d2 <= gnss::chi_square_quantile(kStillGyroBiasGateProbability, 3)) {
      imu0.b_g = level.gyro_bias_b;
      sum.initial_gyro_bias_deg_per_h = b_deg_per_h;
    } else {
      how += fmt_message("; gyro bias not taken from the first still period (mean rate %.0f, %.0f, %.0f deg/h is %.1f "
                         "turn-on sigmas: the IMU moved)",
                         b_deg_per_h.x(), b_deg_per_h.y(), b_deg_per_h.z(), std::sqrt(sum.still_gyro_bias_d2));
    }
  }
  return imu0;
}

namespace {

// An IMU that shows no stance once the walker moves (hand-held, pocket, body-worn; docs/fusion.md §8.2): the share of
// stance samples over the first kNoStanceWindowS after the levelling window's stance ends is below kNoStanceShare.
constexpr double kNoStanceWindowS = 20.0;
constexpr double kNoStanceShare = 0.05;

// First sample after `start` that is not stance (the walker leaves the levelling window), or samples.size().
size_t first_motion_sample(const std::vector<ins::ZuptDecision>& decisions, size_t start) {
  size_t i = start;
  while (i < decisions.size() && decisions[i].stance) ++i;
  return i;
}

bool shows_no_stance(const std::vector<ins::ImuSample>& samples, const std::vector<ins::ZuptDecision>& decisions,
                     size_t moving) {
  size_t n = 0, stance = 0;
  for (size_t i = moving; i < samples.size() && samples[i].t - samples[moving].t <= kNoStanceWindowS; ++i) {
    ++n;
    stance += decisions[i].stance;
  }
  return n > 0 && samples.back().t - samples[moving].t >= kNoStanceWindowS &&
         static_cast<double>(stance) < kNoStanceShare * static_cast<double>(n);
}

// Heading from the GNSS course (docs/fusion.md eq. 8.3): the device faces along the walk, so its yaw at the start is
// the direction from the mean GNSS epoch solution while the walker stood to the first solutions at least D (the
// heading-from-motion distance) further, with σ from the solutions' scatter about that chord.
Expected<HeadingFromMotion> heading_from_gnss_course(const EngineInputs& in, const EngineOptions& o,
                                                     const GnssEpochUpdater& gnss, size_t start, size_t moving,
                                                     const ins::NavState& nav0, EngineSummary& sum, std::string& how) {
  const auto& samples = *in.imu;
  const GpsTime t_start = samples[start].t, t_move = samples[moving].t;
  Vector3d prev = nav0.p_eb_e, still_sum = Vector3d::Zero();
  int n_still = 0;
  std::vector<std::pair<GpsTime, Vector3d>> walk;  // solutions after the walker started moving, in time order
  std::optional<Vector3d> origin;
  for (size_t g = 0; g < in.rover->size(); ++g) {
    const GpsTime t = (*in.rover)[g].time;
    if (t < t_start) continue;
    auto pa = gnss.lsq_position(g, prev);
    if (!pa) continue;
    prev = *pa;
    if (t < t_move) {
      still_sum += *pa;
      ++n_still;
      continue;
    }
    if (!origin) origin = n_still > 0 ? Vector3d(still_sum / n_still) : *pa;
    walk.push_back({t, *pa});
    const Vector3d d = enu_from_ecef(*pa, *origin);
    if (d.head<2>().norm() >= o.heading_init_distance_m && walk.size() >= 5) break;
  }
  if (!origin || walk.size() < 5) {
    return make_error("cannot find the initial heading from the GNSS course: fewer than 5 GNSS epoch solutions after "
                      "the IMU started moving; set initial.yaw_deg");
  }
  // The chord to the mean of the last three solutions.
  Vector3d end = Vector3d::Zero();
  const size_t k0 = walk.size() - 3;
  for (size_t k = k0; k < walk.size(); ++k) end += enu_from_ecef(walk[k].second, *origin);
  end /= 3.0;
  const double length_m = end.head<2>().norm();
  if (length_m < 10.0) {
    return make_error(fmt_message("cannot find the initial heading from the GNSS course: the GNSS track goes %.1f m "
                                  "while the IMU moves (at least 10 m needed); set initial.yaw_deg",
                                  length_m));
  }
  const Eigen::Vector2d u = end.head<2>() / length_m;  // east, north
  double ss = 0.0;
  for (const auto& w : walk) {
    const Vector3d d = enu_from_ecef(w.second, *origin);
    const double across = d.x() * u.y() - d.y() * u.x();
    ss += across * across;
  }
  const double rms = std::sqrt(ss / static_cast<double>(walk.size()));
  const double sigma_yaw = std::clamp(2.0 * rms / length_m, 2.0 * kDegToRad, 30.0 * kDegToRad);
  const double yaw = std::atan2(u.x(), u.y());  // from north, clockwise (east +)
  sum.heading_fit_rms_m = rms;
  sum.heading_init_end = walk.back().first;
  sum.heading_init_distance_m = length_m;
  how += fmt_message("; no stance in the first %.0f s of motion (a hand-held or body-worn IMU): heading from the GNSS "
                     "course over %.0f m (%zu epoch solutions until %s, RMS %.2f m across it, yaw sigma %.1f deg)",
                     kNoStanceWindowS, length_m, walk.size(), walk.back().first.to_string().c_str(), rms,
                     sigma_yaw * kRadToDeg);
  return HeadingFromMotion{wrap_pi(yaw), sigma_yaw};
}

}  // namespace

Expected<HeadingFromMotion> heading_from_motion(const EngineInputs& in, const EngineOptions& o,
                                                const std::vector<ins::ZuptDecision>& decisions,
                                                const GnssEpochUpdater& gnss, size_t start,
                                                const ins::NavState& nav_yaw0, const ins::ImuErrors& imu0,
                                                EngineSummary& sum, std::string& how) {
  const auto& samples = *in.imu;
  // Without stances the INS/ZUPT track below drifts freely: the GNSS course instead (§8.2).
  if (const size_t moving = first_motion_sample(decisions, start);
      moving < samples.size() && shows_no_stance(samples, decisions, moving)) {
    return heading_from_gnss_course(in, o, gnss, start, moving, nav_yaw0, sum, how);
  }
  // Pass 1 (docs/fusion.md §8): the INS/ZUPT track with yaw 0, and at each milestone D, 2D, 4D, … of distance
  // walked (which does not depend on the heading; a GNSS track can "move" D while the person stands, by noise and
  // blunders) a 2D fit of that track onto the GNSS epoch solutions over the same span. The pass stops at the first
  // fit with σ_yaw <= kHeadingInitTargetSigma on a track >= 10 m from its start, or after kHeadingInitDoublings
  // further milestones.
  constexpr double kHeadingInitTargetSigma = 3.0 * kDegToRad;
  constexpr int kHeadingInitDoublings = 5;  // up to 32 D
  EngineOptions ins_only = o;
  ins_only.mode = Mode::kInsOnly;
  ins_only.initial_sigma_yaw_rad = 1e-3;
  ins_only.smoother_enabled = false;
  ins_only.output_rate_hz = o.mechanization_rate_hz;  // the INS antenna track at the GNSS epochs, sampled at 20 Hz
  std::vector<std::pair<GpsTime, Vector3d>> lsq;        // GNSS epoch solutions from the start, in time order
  size_t next_g = 0;
  Vector3d prev = nav_yaw0.p_eb_e;
  Vector3d first = Vector3d::Zero();
  double distance_m = 0.0, theta = 0.0, rms = 0.0, sigma_yaw = 0.0, extent_m = 0.0;
  size_t n_fit = 0;
  int fits = 0;
  GpsTime stop;
  // The fit over the pass-1 outputs so far; false if the track is too short to fit (extent < 10 m or < 5 points).
  auto fit_so_far = [&](const EngineResult& pass1) {
    stop = pass1.epochs.back().t;
    // Largest horizontal distance of the track from its start (the fit needs extent; a loop returns near its start).
    const Vector3d p_beg = pass1.epochs.front().nav.p_eb_e, up = p_beg.normalized();
    extent_m = 0.0;
    for (const auto& e : pass1.epochs) {
      const Vector3d d = e.nav.p_eb_e - p_beg;
      extent_m = std::max(extent_m, (d - d.dot(up) * up).norm());
    }
    for (; next_g < in.rover->size() && (*in.rover)[next_g].time <= stop; ++next_g) {
      if ((*in.rover)[next_g].time < samples[start].t) continue;
      auto pa = gnss.lsq_position(next_g, prev);
      if (!pa) continue;
      prev = *pa;
      if (lsq.empty()) first = *pa;
      lsq.push_back({(*in.rover)[next_g].time, *pa});
    }
    std::vector<Vector3d> src, dst;
    size_t k = 0;
    for (const auto& [t, pa] : lsq) {
      while (k + 1 < pass1.epochs.size() && pass1.epochs[k + 1].t <= t) ++k;
      if (k >= pass1.epochs.size() || std::abs(pass1.epochs[k].t - t) > 0.06) continue;
      const Vector3d p_imu = pass1.epochs[k].nav.p_eb_e;
      src.push_back(enu_from_ecef(p_imu + gnss.lever_e(p_imu), first));
      dst.push_back(enu_from_ecef(pa, first));
    }
    if (src.size() < 5 || extent_m < 10.0) return false;
    std::tie(theta, rms) = fit_yaw(src, dst);
    double spread2 = 0;
    Vector3d mean = Vector3d::Zero();
    for (const auto& p : src) mean += p;
    mean /= static_cast<double>(src.size());
    for (const auto& p : src) spread2 += (p - mean).head<2>().squaredNorm();
    sigma_yaw = std::clamp(2.0 * rms / std::sqrt(std::max(spread2, 1.0)), 1.0 * kDegToRad, 30.0 * kDegToRad);
    n_fit = src.size();
    return true;
  };
  // One pass: at every milestone D, 2D, 4D, … fit what has been walked; stop at a fit with σ_yaw <= target, or at
  // the last milestone. No milestone reached (the data end first): fit whatever was walked.
  bool fitted = false;
  PassOptions p1;
  p1.gnss = false;
  p1.walked_milestone_m = o.heading_init_distance_m;
  p1.at_milestone = [&](const EngineResult& so_far, double milestone_m) {
    if (so_far.epochs.empty()) return false;
    distance_m = milestone_m;
    ++fits;
    fitted = fit_so_far(so_far);
    return (fitted && sigma_yaw <= kHeadingInitTargetSigma) || fits > kHeadingInitDoublings;
  };
  EngineResult pass1;
  ForwardRunner r1(in, ins_only, decisions);
  if (auto ok = r1.run(start, nav_yaw0, imu0, p1, pass1); !ok) {
    return make_error("heading initialization pass: " + ok.error().message);
  }
  if (pass1.epochs.empty()) return make_error("heading initialization pass: no output epoch");
  if (pass1.epochs.back().t > stop) {  // the data ended before the last milestone: fit the whole pass
    distance_m = std::max(distance_m, o.heading_init_distance_m);
    fitted = fit_so_far(pass1);
  }
  if (!fitted) {
    return make_error(fmt_message("cannot find the initial heading from motion: the INS/ZUPT track goes %.1f m from its start "
                                  "(at least 10 m with 5 GNSS epoch solutions needed); set initial.yaw_deg",
                                  extent_m));
  }
  sum.heading_fit_rms_m = rms;
  sum.heading_init_end = stop;
  sum.heading_init_distance_m = distance_m;
  how += fmt_message("; heading from motion: INS/ZUPT track (%.0f m walked) fitted to %zu GNSS epoch solutions until "
                     "%s (fit RMS %.2f m, yaw sigma %.1f deg)",
                     distance_m, n_fit, stop.to_string().c_str(), rms, sigma_yaw * kRadToDeg);
  return HeadingFromMotion{wrap_pi(-theta), sigma_yaw};  // ENU rotation counter-clockwise by theta = heading -theta
}

}  // namespace pednav::fusion
