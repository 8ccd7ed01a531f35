// SPDX-License-Identifier: BSD-2-Clause
// Walker motion: a stride plan from a route (waypoints) or a given track, the foot (IMU) truth and its exact
// IMU samples, and the walker's body/antenna track. Models: docs/sim.md §1-3.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/expected.hpp"
#include "core/time.hpp"
#include "ins/imu.hpp"
#include "ins/nav_state.hpp"
#include "sim/scenario.hpp"

namespace pednav::sim {

/// The local frame of a scenario: NED axes at the origin, fixed to the Earth (a tangent plane, so positions
/// are exact Cartesian offsets; "level" is the origin's level, < 1 mrad off over 7 km).
struct LocalFrame {
  Eigen::Vector3d p0_e = Eigen::Vector3d::Zero();       ///< origin, ECEF [m]
  Eigen::Matrix3d R_e_n0 = Eigen::Matrix3d::Identity(); ///< NED axes at the origin -> ECEF
  Eigen::Vector3d to_e(const Eigen::Vector3d& p_n0) const { return p0_e + R_e_n0 * p_n0; }
  Eigen::Vector3d to_n0(const Eigen::Vector3d& p_e) const { return R_e_n0.transpose() * (p_e - p0_e); }
};
/// Local frame at a geodetic origin.
LocalFrame local_frame(const Geodetic& origin);

/// One stride of the IMU foot: swing from the previous stance pose to this landing pose, then stance.
struct Stride {
  double t_lift_s = 0.0;    ///< swing start, seconds after the scenario start (on the IMU sample grid)
  double swing_s = 0.0;     ///< swing duration [s] (whole IMU periods)
  double stance_s = 0.0;    ///< following stance incl. any pause [s] (whole IMU periods)
  Eigen::Vector3d p_land_n0 = Eigen::Vector3d::Zero();  ///< IMU position at landing, local NED [m]
  double yaw_land = 0.0;    ///< foot heading at landing [rad]
  double pitch_down_rad = 0.0;  ///< toe-off nose-down lobe amplitude [rad]
  double pitch_up_rad = 0.0;    ///< pre-heel-strike nose-up lobe amplitude [rad]
  double roll_rad = 0.0;        ///< roll lobe amplitude [rad]
  double clearance_m = 0.0;     ///< lift lobe amplitude [m]
};

/// A walker's ground point at a time (anchors of the body track).
struct BodyAnchor {
  double t_s = 0.0;                                   ///< seconds after the scenario start
  Eigen::Vector3d p_ground_n0 = Eigen::Vector3d::Zero();  ///< ground point under the walker, local NED [m]
  double route_m = 0.0;                               ///< distance walked [m]
};

/// Strides and body anchors of one scenario.
struct StridePlan {
  Eigen::Vector3d p_start_n0 = Eigen::Vector3d::Zero();  ///< IMU position before the first stride, local NED [m]
  double yaw_start = 0.0;                                ///< foot heading before the first stride [rad]
  std::vector<Stride> strides;
  std::vector<BodyAnchor> body;                          ///< time-ordered, first at 0, last at duration_s
  double duration_s = 0.0;                               ///< whole scenario [s] (whole IMU periods)
  double distance_m = 0.0;                               ///< route distance walked [m]
};

/// Stride plan along the scenario's waypoints (gait options, per-stride randomness from the seed).
Expected<StridePlan> plan_route(const Scenario& scenario, const LocalFrame& frame);
/// Stride plan along the scenario's given antenna track (along-a-track mode); the plan's time 0 is
/// scenario.start.
Expected<StridePlan> plan_track(const Scenario& scenario, const LocalFrame& frame);

/// The walker's antenna track: cubic Hermite through the body anchors, plus height and a vertical bob.
class BodyTrack {
 public:
  BodyTrack(const StridePlan& plan, double antenna_height_m, double bob_m);
  /// Antenna position [m] and velocity [m/s] in the local NED frame, and route distance [m], at t_s.
  void antenna_n0(double t_s, Eigen::Vector3d& p_n0, Eigen::Vector3d& v_n0, double& route_m) const;

 private:
  std::vector<BodyAnchor> a_;
  std::vector<Eigen::Vector3d> tangent_;
  double height_m_, bob_m_;
};

/// Foot truth and its exact IMU samples.
struct WalkTruth {
  std::vector<ins::ImuSample> imu;   ///< exact samples (GPST on the IMU grid)
  std::vector<ins::NavState> nav;    ///< truth at each sample: the ins mechanization of `imu` at the IMU rate
  std::vector<uint8_t> stance;       ///< 1 when the foot is flat (not inside a swing)
};

/// Offset of IMU sample k from the scenario start [ns]: k periods, exact for a rate whose period is a whole number of
/// nanoseconds, rounded to the nanosecond (±0.5 ns) for the others (60 Hz).
int64_t imu_sample_offset_ns(long k, double rate_hz);

/// A designed motion at one instant (ECEF): position, velocity, acceleration, body rate w.r.t. the Earth-fixed local
/// frame on the body axes, attitude.
struct DesignedMotion {
  Eigen::Vector3d p_e, v_e, a_e, omega_nb_b;
  Eigen::Matrix3d R_e_b;
};

/// The exact IMU sample of the design `d` at t, plus a tracking feedback (critically damped, 20 rad/s) of the truth
/// `prev` at the previous sample onto the design there (`d_prev`), which keeps a truth integrated from the samples on
/// the design (docs/sim.md §2); prev == nullptr: no feedback.
ins::ImuSample tracked_sample(GpsTime t, const DesignedMotion& d, const ins::NavState* prev,
                              const DesignedMotion& d_prev);

/// Synthesize the IMU along the plan. Each sample is computed from the designed motion (swing: analytic
/// derivatives of the smooth design anchored at the truth state at lift-off; stance: Earth rate and gravity at
/// the truth state, with a 0.1 s velocity damping), and the truth is the ins mechanization of the samples
/// themselves, so a mechanization of the noise-free IMU from the true initial state reproduces it
/// (docs/sim.md §2).
WalkTruth synthesize_walk(const Scenario& scenario, const LocalFrame& frame, const StridePlan& plan);

/// A device held in the hand (ImuOptions::carry "hand", docs/sim.md §9): pose in the local frame at t_s.
struct HandPose {
  Eigen::Vector3d p_n0 = Eigen::Vector3d::Zero();      ///< device position, local NED [m]
  Eigen::Matrix3d R_n0_b = Eigen::Matrix3d::Identity(); ///< device body axes (x along the walk, z down) -> local NED
  double route_m = 0.0;                                ///< distance walked [m]
  double speed_mps = 0.0;                              ///< horizontal speed of the body [m/s]
};

/// The hand's track: the body track at hand height, facing along the walk (the heading held while standing), with
/// a vertical bob and pitch at the step frequency and a sideways sway, roll and yaw at the stride frequency, their
/// amplitudes growing with the walking speed (none at rest).
class HandTrack {
 public:
  HandTrack(const Scenario& scenario, const StridePlan& plan);
  HandPose at(double t_s) const;

 private:
  BodyTrack body_;
  double stride_hz_ = 1.0, speed_ref_mps_ = 1.0;
  double yaw_dt_s_ = 0.05;
  std::vector<double> yaw_;    ///< unwrapped walking direction on a yaw_dt_s_ grid from 0, smoothed
  std::vector<double> speed_;  ///< body speed on the same grid, smoothed
  double grid_at(const std::vector<double>& g, double t_s) const;
};

/// Synthesize the hand-held IMU along the plan: samples from the hand track's derivatives (central differences over
/// ±1 ms) with a tracking feedback, the truth the ins mechanization of the samples themselves (as the foot's, so a
/// mechanization of the noise-free IMU from the true initial state reproduces it); stance = 1 while the device is at
/// rest (the walker stands and does not turn).
WalkTruth synthesize_hand(const Scenario& scenario, const LocalFrame& frame, const StridePlan& plan);

}  // namespace pednav::sim
