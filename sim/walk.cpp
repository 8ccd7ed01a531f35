// SPDX-License-Identifier: BSD-2-Clause
// Walker motion (docs/sim.md §1-3): stride planning, swing design, exact IMU synthesis, body track.
#include "sim/walk.hpp"

#include <algorithm>
#include <cmath>

#include "core/rotation.hpp"
#include "ins/gravity.hpp"
#include "ins/mechanization.hpp"
#include "sim/random.hpp"

namespace pednav::sim {
namespace {

const Eigen::Vector3d kOmegaIE_e(0.0, 0.0, wgs84::kOmegaIE_radps);
constexpr double kStanceVelocityDamping_s = 0.1;  // stance: residual truth velocity decays with this time constant
constexpr double kTurnLandingThreshold_rad = 20.0 * kDegToRad;  // waypoint turns above this get a landing on it
constexpr double kHeadingChord_m = 0.3;          // chord half-length for the path heading at a landing

// C3 smooth step (7th-order, zero 1st-3rd derivatives at both ends) and its derivatives in s.
struct Poly {
  double v, d1, d2;
};
Poly smooth_step(double s) {
  const double s2 = s * s, s3 = s2 * s, s4 = s3 * s;
  const double q = 1.0 - s;
  return {35 * s4 - 84 * s4 * s + 70 * s4 * s2 - 20 * s4 * s3, 140 * s3 * q * q * q,
          420 * s2 * q * q * (1.0 - 2.0 * s)};
}
// Bump 256 u^4 (1-u)^4 on the window [a, b] of s (peak 1 at the middle, C3 at the window ends), derivatives in s.
Poly bump(double s, double a, double b) {
  if (s <= a || s >= b) return {0, 0, 0};
  const double L = b - a, u = (s - a) / L, q = 1.0 - u;
  const double uq = u * q;
  return {256 * uq * uq * uq * uq, 1024 * uq * uq * uq * (1.0 - 2.0 * u) / L,
          1024 * uq * uq * (3.0 * (1.0 - 2.0 * u) * (1.0 - 2.0 * u) - 2.0 * uq) / (L * L)};
}
constexpr double kPitchDownEnd = 0.6, kPitchUpStart = 0.45;

double quantize_time(double t_s, double rate_hz, int min_periods) {
  return std::max<double>(min_periods, std::round(t_s * rate_hz)) / rate_hz;
}
Eigen::Vector3d right_of(double yaw) { return {-std::sin(yaw), std::cos(yaw), 0.0}; }
double heading_of(const Eigen::Vector3d& d) { return std::atan2(d.y(), d.x()); }

// A polyline in local NED with horizontal arc length.
struct Polyline {
  std::vector<Eigen::Vector3d> p;
  std::vector<double> s;
  double length() const { return s.empty() ? 0.0 : s.back(); }
  Eigen::Vector3d at(double sq) const {
    if (sq <= 0.0) return p.front();
    if (sq >= s.back()) return p.back();
    const auto it = std::upper_bound(s.begin(), s.end(), sq);
    const size_t i = static_cast<size_t>(it - s.begin());
    const double w = (sq - s[i - 1]) / std::max(1e-12, s[i] - s[i - 1]);
    return p[i - 1] + w * (p[i] - p[i - 1]);
  }
  double heading_at(double sq) const {
    const Eigen::Vector3d d = at(std::min(length(), sq + kHeadingChord_m)) - at(std::max(0.0, sq - kHeadingChord_m));
    return heading_of(d);
  }
};
Polyline make_polyline(const std::vector<Eigen::Vector3d>& pts) {
  Polyline pl;
  for (const auto& q : pts) {
    if (!pl.p.empty() && (q - pl.p.back()).head<2>().norm() < 1e-9) continue;
    pl.s.push_back(pl.p.empty() ? 0.0 : pl.s.back() + (q - pl.p.back()).head<2>().norm());
    pl.p.push_back(q);
  }
  return pl;
}

// Builder shared by the route and track planners.
struct Planner {
  const Scenario& sc;
  Rng rng;
  StridePlan plan;
  double t = 0.0;        // current time (end of the last stance)
  double yaw = 0.0;      // current foot heading
  Eigen::Vector3d ground = Eigen::Vector3d::Zero();  // ground point under the walker now
  double route_m = 0.0;
  double nominal_stance_s;

  explicit Planner(const Scenario& s) : sc(s), rng(s.seed, kStreamGait), nominal_stance_s(s.gait.cycle_s * s.gait.stance_fraction) {}

  Eigen::Vector3d foot_at(const Eigen::Vector3d& g, double y) const {
    return g + sc.gait.foot_offset_m * right_of(y) + Eigen::Vector3d(0, 0, -sc.gait.imu_height_m);
  }
  void start(const Eigen::Vector3d& g, double y) {
    ground = g;
    yaw = y;
    plan.p_start_n0 = foot_at(g, y);
    plan.yaw_start = y;
    t = quantize_time(sc.static_start_s, sc.imu.rate_hz, 1);
    plan.body.push_back({0.0, g, 0.0});
    plan.body.push_back({t, g, 0.0});
  }
  // One stride to ground point g with heading y; in_place: a turning stride; extra stance (pause) [s].
  void stride(const Eigen::Vector3d& g, double y, bool in_place, double pause_s) {
    const GaitOptions& ga = sc.gait;
    Stride st;
    st.t_lift_s = t;
    st.swing_s = quantize_time(ga.cycle_s * (1.0 - ga.stance_fraction) * (1.0 + ga.cycle_sd_fraction * rng.normal()),
                               sc.imu.rate_hz, 4);
    const double stance = quantize_time(nominal_stance_s * (1.0 + ga.cycle_sd_fraction * rng.normal()), sc.imu.rate_hz, 2);
    st.stance_s = stance + quantize_time(pause_s, sc.imu.rate_hz, 0);
    st.p_land_n0 = foot_at(g, y);
    st.yaw_land = y;
    const double scale = in_place ? 0.3 : 1.0;
    // Lobe amplitudes so that the peak pitch rate max_s |d pitch/ds| / T_swing is the drawn target.
    const double rate = ga.pitch_rate_peak_radps * (1.0 + 0.1 * rng.normal());
    const double up_ratio = 0.35 * (1.0 + 0.1 * rng.normal());
    double slope = 0.0;  // max |d/ds (-b1 + up_ratio b2)| for a unit nose-down lobe
    for (int i = 0; i <= 400; ++i) {
      const double s = i / 400.0;
      slope = std::max(slope, std::abs(-bump(s, 0.0, kPitchDownEnd).d1 + up_ratio * bump(s, kPitchUpStart, 1.0).d1));
    }
    st.pitch_down_rad = scale * std::min(1.2, rate * st.swing_s / slope);
    st.pitch_up_rad = up_ratio * st.pitch_down_rad;
    st.roll_rad = scale * 0.05 * rng.normal();
    st.clearance_m = (in_place ? 0.5 : 1.0) * ga.clearance_m * std::max(0.3, 1.0 + 0.1 * rng.normal());
    plan.strides.push_back(st);
    const double t_land = t + st.swing_s;
    route_m += (g - ground).head<2>().norm();
    ground = g;
    yaw = y;
    // The body passes over the stance foot at mid-stance (Perry 1992); a pause adds a second anchor.
    plan.body.push_back({t_land + 0.5 * std::min(stance, st.stance_s), g, route_m});
    if (st.stance_s > 2.0 * nominal_stance_s) plan.body.push_back({t_land + st.stance_s - 0.5 * nominal_stance_s, g, route_m});
    t = t_land + st.stance_s;
  }
  void turn_to(double y_new) {
    const double d = wrap_pi(y_new - yaw);
    if (std::abs(d) <= sc.gait.max_turn_per_stride_rad) return;
    const int n = static_cast<int>(std::ceil(std::abs(d) / sc.gait.max_turn_per_stride_rad));
    const double y0 = yaw;
    for (int j = 1; j <= n; ++j) stride(ground, wrap_pi(y0 + d * j / n), true, 0.0);
  }
  void finish() {
    const double end = t + quantize_time(sc.static_end_s, sc.imu.rate_hz, 1);
    if (plan.body.back().t_s < end) plan.body.push_back({end, ground, route_m});
    plan.duration_s = end;
    plan.distance_m = route_m;
  }
};

// The designed swing at time ts (seconds after the start): analytic position, velocity, acceleration,
// attitude and body rate. Position: smooth step from the lift-off point to the landing point plus a lift lobe;
// attitude: z-y-x Euler angles (roll/pitch lobes, yaw smooth step) in the local NED frame n0.
using Design = DesignedMotion;
Design design(const Stride& st, const Eigen::Vector3d& pA, const Eigen::Vector3d& eulerA, double ts, const LocalFrame& frame) {
  const double T = st.swing_s, s = std::clamp((ts - st.t_lift_s) / T, 0.0, 1.0);
  const Poly sg = smooth_step(s), b0 = bump(s, 0.0, 1.0), b1 = bump(s, 0.0, kPitchDownEnd), b2 = bump(s, kPitchUpStart, 1.0);
  const Eigen::Vector3d dp = st.p_land_n0 - pA, up(0.0, 0.0, -st.clearance_m);
  const Eigen::Vector3d p_n = pA + dp * sg.v + up * b0.v;
  const Eigen::Vector3d v_n = (dp * sg.d1 + up * b0.d1) / T;
  const Eigen::Vector3d a_n = (dp * sg.d2 + up * b0.d2) / (T * T);
  const double dyaw = wrap_pi(st.yaw_land - eulerA.z());
  const double roll = eulerA.x() * (1.0 - sg.v) + st.roll_rad * b0.v;
  const double pitch = eulerA.y() * (1.0 - sg.v) - st.pitch_down_rad * b1.v + st.pitch_up_rad * b2.v;
  const double yaw = eulerA.z() + dyaw * sg.v;
  const double droll = (-eulerA.x() * sg.d1 + st.roll_rad * b0.d1) / T;
  const double dpitch = (-eulerA.y() * sg.d1 - st.pitch_down_rad * b1.d1 + st.pitch_up_rad * b2.d1) / T;
  const double dyaw_dt = dyaw * sg.d1 / T;
  // Body rates of the z-y-x Euler sequence (Groves 2013 eq. 2.58 inverted).
  const double sr = std::sin(roll), cr = std::cos(roll), sp = std::sin(pitch), cp = std::cos(pitch);
  Design d;
  d.omega_nb_b = Eigen::Vector3d(droll - dyaw_dt * sp, dpitch * cr + dyaw_dt * sr * cp, -dpitch * sr + dyaw_dt * cr * cp);
  d.R_e_b = frame.R_e_n0 * R_n_b_from_euler(roll, pitch, yaw);
  d.p_e = frame.to_e(p_n);
  d.v_e = frame.R_e_n0 * v_n;
  d.a_e = frame.R_e_n0 * a_n;
  return d;
}

}  // namespace

LocalFrame local_frame(const Geodetic& origin) {
  LocalFrame f;
  f.p0_e = ecef_from_geodetic(origin);
  f.R_e_n0 = R_e_n(origin.lat, origin.lon);
  return f;
}

Expected<StridePlan> plan_route(const Scenario& sc, const LocalFrame& /*frame*/) {
  if (sc.waypoints.size() < 2) return make_error("route: at least 2 waypoints are needed");
  std::vector<Eigen::Vector3d> g;
  for (const auto& w : sc.waypoints) g.emplace_back(w.p_enu_m.y(), w.p_enu_m.x(), -w.p_enu_m.z());
  // Forced landings: start, end, pauses and turns above the threshold.
  std::vector<size_t> forced{0};
  for (size_t i = 1; i + 1 < g.size(); ++i) {
    const Eigen::Vector3d a = g[i] - g[i - 1], b = g[i + 1] - g[i];
    const bool turn = a.head<2>().norm() > 1e-9 && b.head<2>().norm() > 1e-9 &&
                      std::abs(wrap_pi(heading_of(b) - heading_of(a))) > kTurnLandingThreshold_rad;
    if (turn || sc.waypoints[i].pause_s > 0.0) forced.push_back(i);
  }
  forced.push_back(g.size() - 1);

  Planner pl(sc);
  const double stride_nom = sc.gait.speed_mps * sc.gait.cycle_s;
  bool started = false;
  for (size_t k = 0; k + 1 < forced.size(); ++k) {
    const Polyline path = make_polyline({g.begin() + static_cast<long>(forced[k]), g.begin() + static_cast<long>(forced[k + 1]) + 1});
    const double L = path.length();
    if (L < 1e-6) continue;
    const double y0 = path.heading_at(0.0);
    if (!started) {
      pl.start(path.p.front(), y0);
      started = true;
    }
    pl.turn_to(y0);
    const int n = std::max(1, static_cast<int>(std::lround(L / stride_nom)));
    std::vector<double> len(static_cast<size_t>(n));
    double sum = 0.0;
    for (auto& l : len) sum += (l = std::max(0.2, 1.0 + sc.gait.stride_sd_fraction * pl.rng.normal()));
    double s = 0.0;
    for (int j = 0; j < n; ++j) {
      s += len[static_cast<size_t>(j)] / sum * L;
      if (j == n - 1) s = L;
      const double y = j == n - 1 ? heading_of(path.at(L) - path.at(L - kHeadingChord_m)) : path.heading_at(s);
      pl.stride(path.at(s), y, false, j == n - 1 ? sc.waypoints[forced[k + 1]].pause_s : 0.0);
    }
  }
  if (!started) return make_error("route: the waypoints do not span any horizontal distance");
  pl.finish();
  return pl.plan;
}

Expected<StridePlan> plan_track(const Scenario& sc, const LocalFrame& frame) {
  if (sc.track.size() < 2) return make_error("track: at least 2 points are needed");
  const GpsTime t0 = sc.start;
  // Ground track smoothed with a Gaussian kernel on a 0.5 s grid: RTK float epochs jitter, and a wider kernel cuts the
  // corners (sigma 1 s put the simulated antenna 0.10 m RMS, 0.84 m at most, off the fixed Galway epochs; 0.5 s:
  // 0.03 m, 0.29 m), which puts the foot IMU off the track the real carrier phase measures (docs/sim.md §3).
  constexpr double kKernelSigma_s = 0.5;
  const double span = sc.track.back().t - t0;
  if (!(span > 10.0)) return make_error("track: it ends less than 10 s after the scenario start");
  std::vector<double> ts;
  std::vector<Eigen::Vector3d> gs;
  const double h = sc.gnss.antenna_height_m;
  for (double tq = 0.0; tq <= span; tq += 0.5) {
    double wsum = 0.0;
    Eigen::Vector3d acc = Eigen::Vector3d::Zero();
    for (const auto& q : sc.track) {
      const double d = (q.t - t0) - tq;
      if (std::abs(d) > 3.0 * kKernelSigma_s) continue;
      const double w = std::exp(-0.5 * d * d / (kKernelSigma_s * kKernelSigma_s));
      acc += w * frame.to_n0(q.p_e);
      wsum += w;
    }
    if (wsum < 0.05) {  // a gap in the track: hold the last point
      if (gs.empty()) continue;
      acc = gs.back();
    } else {
      acc /= wsum;
      acc.z() += h;
    }
    ts.push_back(tq);
    gs.push_back(acc);
  }
  if (gs.size() < 4) return make_error("track: too few points near the scenario start");
  auto ground_at = [&](double tq) {
    if (tq <= ts.front()) return gs.front();
    if (tq >= ts.back()) return gs.back();
    const size_t i = static_cast<size_t>(std::upper_bound(ts.begin(), ts.end(), tq) - ts.begin());
    const double w = (tq - ts[i - 1]) / (ts[i] - ts[i - 1]);
    return Eigen::Vector3d(gs[i - 1] + w * (gs[i] - gs[i - 1]));
  };
  auto velocity_at = [&](double tq) { return Eigen::Vector3d((ground_at(tq + 1.0) - ground_at(tq - 1.0)) / 2.0); };
  constexpr double kMovingSpeed_mps = 0.25;
  const double end_s = ts.back() - std::max(1.0, sc.static_end_s);

  // A shuffle step re-centres a standing walker the track has drifted away from by more than this.
  constexpr double kStandingDrift_m = 0.15;
  Planner pl(sc);
  pl.start(ground_at(0.0), heading_of(velocity_at(sc.static_start_s + 2.0)));
  while (pl.t + sc.gait.cycle_s < end_s) {
    // Land where the body will be at mid-stance of this stride.
    const double t_mid = pl.t + sc.gait.cycle_s * (1.0 - 0.5 * sc.gait.stance_fraction);
    const Eigen::Vector3d g = ground_at(t_mid);
    const Eigen::Vector3d v = velocity_at(t_mid);
    const bool moving = v.head<2>().norm() >= kMovingSpeed_mps;
    if (!moving && (g - pl.ground).head<2>().norm() < kStandingDrift_m) {  // standing: wait one stance period
      pl.t += quantize_time(pl.nominal_stance_s, sc.imu.rate_hz, 1);
      continue;
    }
    // Every stride lands on the track, turning by at most max_turn_per_stride (a sharper corner of the track is taken
    // over several strides that keep up with it: in-place turning strides would leave the antenna metres ahead).
    const double y_track = moving ? heading_of(v) : pl.yaw;
    const double max_turn = sc.gait.max_turn_per_stride_rad;
    const double turn = std::clamp(wrap_pi(y_track - pl.yaw), -max_turn, max_turn);
    pl.stride(g, wrap_pi(pl.yaw + turn), false, 0.0);
  }
  // The body follows the smoothed track itself (the antenna's truth).
  pl.plan.body.clear();
  double route = 0.0;
  for (size_t i = 0; i < ts.size(); ++i) {
    if (i > 0) route += (gs[i] - gs[i - 1]).head<2>().norm();
    pl.plan.body.push_back({ts[i], gs[i], route});
  }
  pl.finish();
  pl.plan.duration_s = std::floor(std::min(pl.plan.duration_s, ts.back()) * sc.imu.rate_hz) / sc.imu.rate_hz;
  return pl.plan;
}

BodyTrack::BodyTrack(const StridePlan& plan, double antenna_height_m, double bob_m)
    : a_(plan.body), height_m_(antenna_height_m), bob_m_(bob_m) {
  // Catmull-Rom tangents, zero next to a standing anchor (no overshoot at starts and stops).
  tangent_.assign(a_.size(), Eigen::Vector3d::Zero());
  for (size_t i = 1; i + 1 < a_.size(); ++i) {
    const bool still = (a_[i].p_ground_n0 - a_[i - 1].p_ground_n0).norm() < 1e-6 ||
                       (a_[i + 1].p_ground_n0 - a_[i].p_ground_n0).norm() < 1e-6;
    if (!still) tangent_[i] = (a_[i + 1].p_ground_n0 - a_[i - 1].p_ground_n0) / (a_[i + 1].t_s - a_[i - 1].t_s);
  }
}

void BodyTrack::antenna_n0(double t_s, Eigen::Vector3d& p, Eigen::Vector3d& v, double& route_m) const {
  const Eigen::Vector3d up_h(0.0, 0.0, -height_m_);
  if (t_s <= a_.front().t_s || a_.size() == 1) {
    p = a_.front().p_ground_n0 + up_h;
    v.setZero();
    route_m = a_.front().route_m;
    return;
  }
  if (t_s >= a_.back().t_s) {
    p = a_.back().p_ground_n0 + up_h;
    v.setZero();
    route_m = a_.back().route_m;
    return;
  }
  const size_t i = static_cast<size_t>(std::upper_bound(a_.begin(), a_.end(), t_s, [](double t, const BodyAnchor& b) {
                     return t < b.t_s;
                   }) - a_.begin()) - 1;
  const BodyAnchor &A = a_[i], &B = a_[i + 1];
  const double T = B.t_s - A.t_s, u = (t_s - A.t_s) / T;
  // Cubic Hermite basis and derivatives.
  const double h00 = 2 * u * u * u - 3 * u * u + 1, h10 = u * u * u - 2 * u * u + u, h01 = -2 * u * u * u + 3 * u * u,
               h11 = u * u * u - u * u;
  const double d00 = 6 * u * u - 6 * u, d10 = 3 * u * u - 4 * u + 1, d01 = -6 * u * u + 6 * u, d11 = 3 * u * u - 2 * u;
  p = h00 * A.p_ground_n0 + h10 * T * tangent_[i] + h01 * B.p_ground_n0 + h11 * T * tangent_[i + 1] + up_h;
  v = (d00 * A.p_ground_n0 + d10 * T * tangent_[i] + d01 * B.p_ground_n0 + d11 * T * tangent_[i + 1]) / T;
  route_m = A.route_m + u * (B.route_m - A.route_m);
  if ((B.p_ground_n0 - A.p_ground_n0).norm() > 1e-6) {  // walking: the body bobs twice per stride
    const double w = 2.0 * kPi * 2.0 / T;
    p.z() -= bob_m_ * std::sin(w * (t_s - A.t_s));
    v.z() -= bob_m_ * w * std::cos(w * (t_s - A.t_s));
  }
}

int64_t imu_sample_offset_ns(long k, double rate_hz) {
  const int64_t period_ns = std::llround(1e9 / rate_hz);
  if (std::abs(1e9 / rate_hz - static_cast<double>(period_ns)) <= 1e-6) return k * period_ns;
  return std::llround(static_cast<long double>(k) * 1e9L / rate_hz);
}

ins::ImuSample tracked_sample(GpsTime t, const DesignedMotion& d, const ins::NavState* prev,
                              const DesignedMotion& d_prev) {
  constexpr double kTrackPos_per_s2 = 400.0;  // natural frequency 20 rad/s, critically damped
  constexpr double kTrackVel_per_s = 40.0;
  constexpr double kTrackAtt_per_s = 20.0;    // attitude [1/s]
  Eigen::Vector3d a_fb = Eigen::Vector3d::Zero(), att_fb = Eigen::Vector3d::Zero();
  if (prev) {
    a_fb = kTrackPos_per_s2 * (d_prev.p_e - prev->p_eb_e) + kTrackVel_per_s * (d_prev.v_e - prev->v_eb_e);
    att_fb = kTrackAtt_per_s * so3_log(prev->R_e_b().transpose() * d_prev.R_e_b);
  }
  ins::ImuSample m;
  m.t = t;
  m.omega_ib_b = d.omega_nb_b + d.R_e_b.transpose() * kOmegaIE_e + att_fb;  // the local frame is fixed to the Earth
  m.f_ib_b = d.R_e_b.transpose() * (d.a_e + a_fb + 2.0 * kOmegaIE_e.cross(d.v_e) - ins::gravity_ecef(d.p_e));
  return m;
}

WalkTruth synthesize_walk(const Scenario& sc, const LocalFrame& frame, const StridePlan& plan) {
  WalkTruth out;
  const double rate = sc.imu.rate_hz;
  const long n = std::lround(plan.duration_s * rate) + 1;
  out.imu.reserve(static_cast<size_t>(n));
  out.nav.reserve(static_cast<size_t>(n));
  out.stance.reserve(static_cast<size_t>(n));
  const Eigen::Matrix3d& R_e_n0 = frame.R_e_n0;

  ins::NavState x;
  x.t = sc.start;
  x.p_eb_e = frame.to_e(plan.p_start_n0);
  x.q_e_b = Eigen::Quaterniond(R_e_n0 * R_n_b_from_euler(0.0, 0.0, plan.yaw_start)).normalized();

  // Stance sample at the truth state: Earth rate, gravity, Coriolis and a velocity damping.
  auto stance_sample = [&](const ins::NavState& s, GpsTime t) {
    const Eigen::Matrix3d R_b_e = s.R_e_b().transpose();
    ins::ImuSample m;
    m.t = t;
    m.omega_ib_b = R_b_e * kOmegaIE_e;
    const Eigen::Vector3d a_e = -s.v_eb_e / kStanceVelocityDamping_s;
    m.f_ib_b = R_b_e * (a_e + 2.0 * kOmegaIE_e.cross(s.v_eb_e) - ins::gravity_ecef(s.p_eb_e));
    return m;
  };

  ins::IncrementOptions io;
  io.rate_hz = rate;
  ins::IncrementIntegrator integ(io);
  size_t si = 0;  // current stride
  Eigen::Vector3d pA = Eigen::Vector3d::Zero(), eulerA = Eigen::Vector3d::Zero();
  long anchored = -1;
  for (long k = 0; k < n; ++k) {
    const GpsTime t = sc.start.plus_ns(imu_sample_offset_ns(k, rate));
    const double ts = static_cast<double>(k) / rate;
    while (si < plan.strides.size() && k > std::lround((plan.strides[si].t_lift_s + plan.strides[si].swing_s) * rate)) ++si;
    ins::ImuSample m;
    bool in_swing = false;
    if (si < plan.strides.size()) {
      const Stride& st = plan.strides[si];
      const long k_lift = std::lround(st.t_lift_s * rate), k_land = std::lround((st.t_lift_s + st.swing_s) * rate);
      in_swing = k > k_lift && k <= k_land;
      if (in_swing) {
        if (anchored != static_cast<long>(si)) {  // anchor the design at the truth at lift-off
          const ins::NavState& xa = out.nav[static_cast<size_t>(k_lift)];
          pA = frame.to_n0(xa.p_eb_e);
          eulerA = euler_from_R_n_b(R_e_n0.transpose() * xa.R_e_b());
          anchored = static_cast<long>(si);
        }
        const Design d = design(st, pA, eulerA, ts, frame);
        // Tracking feedback on the truth at the previous sample keeps the integrated truth on the design
        // (integration error of the sampled rates); the truth stays the mechanization of these very samples.
        m = tracked_sample(t, d, &out.nav.back(), design(st, pA, eulerA, ts - 1.0 / rate, frame));
      }
    }
    if (!in_swing) m = stance_sample(k == 0 ? x : out.nav.back(), t);
    if (k == 0) {
      integ.push(m, [](const ins::ImuIncrement&) {});
    } else {
      integ.push(m, [&](const ins::ImuIncrement& inc) { x = ins::mechanize(x, inc); });
    }
    out.imu.push_back(m);
    out.nav.push_back(x);
    out.stance.push_back(in_swing ? 0 : 1);
  }
  return out;
}

}  // namespace pednav::sim
