// SPDX-License-Identifier: BSD-2-Clause
// WGS84 gravity in ECEF: J2 gravitation (Groves 2013 eq. 2.142) plus the centrifugal term (Groves 2013 §2.4.7).
#pragma once

#include <Eigen/Core>

namespace pednav::ins {

/// Gravitational acceleration gamma_ib_e [m/s^2] at ECEF position p_e [m], J2 model (Groves 2013 eq. 2.142).
Eigen::Vector3d gravitation_ecef(const Eigen::Vector3d& p_e);
/// Gravity g_b_e = gamma - omega_ie x (omega_ie x p) [m/s^2] at ECEF position p_e [m] (Groves 2013 §2.4.7):
/// the acceleration a plumb bob at rest on the Earth feels; |g| = 9.7803 m/s^2 on the equator at h = 0.
Eigen::Vector3d gravity_ecef(const Eigen::Vector3d& p_e);
/// Gravity gradient d g_e / d p_e [1/s^2] at p_e [m]: point-mass gravitation gradient
/// -GM/r^3 (I - 3 u u^T) plus the centrifugal gradient -[omega_ie x]^2 (J2 part omitted: < 0.3 % of it).
Eigen::Matrix3d gravity_gradient_ecef(const Eigen::Vector3d& p_e);

}  // namespace pednav::ins
