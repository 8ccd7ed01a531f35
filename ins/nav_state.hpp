// SPDX-License-Identifier: BSD-2-Clause
// The nominal (whole-state) INS navigation solution in ECEF.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/time.hpp"

namespace pednav::ins {

/// Position, velocity and attitude of the IMU body frame b in ECEF at time t.
struct NavState {
  GpsTime t;                                              ///< epoch (GPST)
  Eigen::Vector3d p_eb_e = Eigen::Vector3d::Zero();       ///< position of b in ECEF [m]
  Eigen::Vector3d v_eb_e = Eigen::Vector3d::Zero();       ///< velocity of b w.r.t. Earth, resolved in e [m/s]
  Eigen::Quaterniond q_e_b = Eigen::Quaterniond::Identity();  ///< attitude, v_e = q_e_b * v_b (Hamilton)

  /// Rotation matrix R_e_b (maps b-resolved vectors into e).
  Eigen::Matrix3d R_e_b() const { return q_e_b.toRotationMatrix(); }
};

}  // namespace pednav::ins
