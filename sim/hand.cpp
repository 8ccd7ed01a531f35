// SPDX-License-Identifier: BSD-2-Clause
// A device carried in the hand (docs/sim.md §9): the walker's body track at hand height with the swing of a hand
// that holds a phone in front of the body, and its exact IMU samples (sim/walk.hpp HandTrack, synthesize_hand).
#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "ins/mechanization.hpp"
#include "sim/walk.hpp"

namespace pednav::sim {
namespace {

// The hand: 1.1 m above the ground, 0.3 m ahead of the body; at the reference walking speed it bobs ±2.5 cm and
// pitches ±3° at the step frequency (twice per stride), sways ±2 cm sideways and rolls ±3° and yaws ±2° at the
// stride frequency; the amplitudes follow a smoothstep of the walking speed over the gait's (none at rest).
constexpr double kHandHeightM = 1.1, kHandAheadM = 0.3;
constexpr double kBobM = 0.025, kSwayM = 0.02;
constexpr double kPitchRad = 3.0 * kDegToRad, kRollRad = 3.0 * kDegToRad, kYawRad = 2.0 * kDegToRad;
constexpr double kMinWalkingSpeedMps = 0.2;  // below this the walking direction is held
constexpr double kDiffStepS = 1e-3;          // central differences of the track for the IMU samples
constexpr double kTurnSmoothingS = 1.0;      // the device turns with the walker over about this long

}  // namespace

HandTrack::HandTrack(const Scenario& sc, const StridePlan& plan)
    : body_(plan, kHandHeightM, 0.0), stride_hz_(1.0 / sc.gait.cycle_s), speed_ref_mps_(sc.gait.speed_mps) {
  // Walking direction on a grid, unwrapped; held through stops, the first one back-filled to the start.
  const long n = static_cast<long>(std::ceil(plan.duration_s / yaw_dt_s_)) + 2;
  yaw_.assign(static_cast<size_t>(n), NAN);
  speed_.assign(static_cast<size_t>(n), 0.0);
  double last = NAN;
  for (long k = 0; k < n; ++k) {
    Eigen::Vector3d p, v;
    double route = 0.0;
    body_.antenna_n0(static_cast<double>(k) * yaw_dt_s_, p, v, route);
    speed_[static_cast<size_t>(k)] = v.head<2>().norm();
    if (v.head<2>().norm() >= kMinWalkingSpeedMps) {
      double y = std::atan2(v.y(), v.x());
      if (std::isfinite(last)) y = last + std::remainder(y - last, 2.0 * kPi);
      last = y;
    }
    yaw_[static_cast<size_t>(k)] = last;
  }
  double first = plan.yaw_start;
  for (double y : yaw_) {
    if (std::isfinite(y)) {
      first = y;
      break;
    }
  }
  for (auto& y : yaw_) {
    if (!std::isfinite(y)) y = first;
    else break;
  }
  // A person turns the device over about a second, not at the sample where the walking direction changes (a stop
  // and an in-place turn at a corner): two passes of a centred 1-s moving average (triangular, 2 s support).
  // The swing amplitudes follow the walking speed the same way (the body track's speed has corners at its anchors).
  const long half = std::lround(kTurnSmoothingS / (2.0 * yaw_dt_s_));
  for (auto* grid : {&yaw_, &speed_}) {
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<double> sm(grid->size());
      for (long k = 0; k < static_cast<long>(grid->size()); ++k) {
        double sum = 0.0;
        for (long j = k - half; j <= k + half; ++j) {
          sum += (*grid)[static_cast<size_t>(std::clamp(j, 0L, static_cast<long>(grid->size()) - 1))];
        }
        sm[static_cast<size_t>(k)] = sum / static_cast<double>(2 * half + 1);
      }
      grid->swap(sm);
    }
  }
}

double HandTrack::grid_at(const std::vector<double>& g, double t_s) const {
  // Catmull-Rom through the grid: continuous first derivative.
  const double x = std::clamp(t_s / yaw_dt_s_, 0.0, static_cast<double>(g.size() - 1));
  const size_t i = std::min(static_cast<size_t>(x), g.size() - 2);
  const double u = x - static_cast<double>(i);
  const double y0 = g[i > 0 ? i - 1 : 0], y1 = g[i], y2 = g[i + 1], y3 = g[std::min(i + 2, g.size() - 1)];
  const double m1 = 0.5 * (y2 - y0), m2 = 0.5 * (y3 - y1);
  return (2 * u * u * u - 3 * u * u + 1) * y1 + (u * u * u - 2 * u * u + u) * m1 + (-2 * u * u * u + 3 * u * u) * y2 +
         (u * u * u - u * u) * m2;
}

HandPose HandTrack::at(double t_s) const {
  HandPose h;
  Eigen::Vector3d p, v;
  body_.antenna_n0(t_s, p, v, h.route_m);
  h.speed_mps = v.head<2>().norm();
  // Heading and swing amplitude from their smoothed grids with a continuous rate, so that the hand's velocity
  // (kHandAheadM times the heading rate, the amplitudes' rates) has no steps and the specific force no spikes; the
  // amplitude is a smoothstep of the smoothed speed over the gait's (zero rate at rest and at full swing).
  const double yaw = grid_at(yaw_, t_s);
  const double r = std::clamp(grid_at(speed_, t_s) / speed_ref_mps_, 0.0, 1.0), s = r * r * (3.0 - 2.0 * r);
  const double stride = 2.0 * kPi * stride_hz_ * t_s, step = 2.0 * stride;
  const Eigen::Vector3d fwd(std::cos(yaw), std::sin(yaw), 0.0), right(-std::sin(yaw), std::cos(yaw), 0.0);
  h.p_n0 = p + kHandAheadM * fwd + s * kSwayM * std::sin(stride) * right + Eigen::Vector3d(0, 0, s * kBobM * std::sin(step));
  h.R_n0_b = R_n_b_from_euler(s * kRollRad * std::sin(stride), s * kPitchRad * std::cos(step),
                              yaw + s * kYawRad * std::sin(stride));
  return h;
}

namespace {

// The designed kinematics of the hand at ts (central differences of the track over ±kDiffStepS).
struct HandDesign : DesignedMotion {
  double speed_mps = 0.0;
};

HandDesign hand_design(const HandTrack& hand, const LocalFrame& frame, double ts) {
  const double h = kDiffStepS;
  const HandPose a = hand.at(ts - h), b = hand.at(ts), c = hand.at(ts + h);
  HandDesign d;
  d.p_e = frame.to_e(b.p_n0);
  d.v_e = frame.R_e_n0 * (c.p_n0 - a.p_n0) / (2.0 * h);
  d.a_e = frame.R_e_n0 * (c.p_n0 - 2.0 * b.p_n0 + a.p_n0) / (h * h);
  d.R_e_b = frame.R_e_n0 * b.R_n0_b;
  // Body rate w.r.t. the Earth-fixed local frame (n0 is fixed to the Earth), on the body axes.
  d.omega_nb_b = so3_log(a.R_n0_b.transpose() * c.R_n0_b) / (2.0 * h);
  d.speed_mps = b.speed_mps;
  return d;
}

}  // namespace

WalkTruth synthesize_hand(const Scenario& sc, const LocalFrame& frame, const StridePlan& plan) {
  WalkTruth out;
  const HandTrack hand(sc, plan);
  const double rate = sc.imu.rate_hz;
  const long n = std::lround(plan.duration_s * rate) + 1;
  out.imu.reserve(static_cast<size_t>(n));
  out.nav.reserve(static_cast<size_t>(n));
  out.stance.reserve(static_cast<size_t>(n));
  ins::IncrementOptions io;
  io.rate_hz = rate;
  ins::IncrementIntegrator integ(io);
  ins::NavState x;
  for (long k = 0; k < n; ++k) {
    const int64_t offset_ns = imu_sample_offset_ns(k, rate);
    const GpsTime t = sc.start.plus_ns(offset_ns);
    const double ts = static_cast<double>(offset_ns) * 1e-9;
    const HandDesign d = hand_design(hand, frame, ts);
    if (k == 0) {
      x.t = t;
      x.p_eb_e = d.p_e;
      x.v_eb_e = d.v_e;
      x.q_e_b = Eigen::Quaterniond(d.R_e_b).normalized();
    }
    // The truth is the mechanization of these very samples; the feedback keeps it on the design.
    const ins::NavState* prev = k == 0 ? nullptr : &out.nav.back();
    const ins::ImuSample m =
        tracked_sample(t, d, prev, prev ? hand_design(hand, frame, static_cast<double>(prev->t - sc.start)) : d);
    if (k == 0) {
      integ.push(m, [](const ins::ImuIncrement&) {});
    } else {
      integ.push(m, [&](const ins::ImuIncrement& inc) { x = ins::mechanize(x, inc); });
    }
    out.imu.push_back(m);
    out.nav.push_back(x);
    out.stance.push_back(d.v_e.norm() < 1e-3 && d.omega_nb_b.norm() < 1e-3 ? 1 : 0);  // the device at rest
  }
  return out;
}

}  // namespace pednav::sim
