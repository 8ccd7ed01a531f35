// SPDX-License-Identifier: BSD-2-Clause
// Rotations: Hamilton quaternions, rotation matrices, SO(3) exp/log, skew, Euler angles (I/O only).
// Convention (docs/conventions.md): R_a_b maps b-resolved vectors into a: v_a = R_a_b * v_b.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pednav {

/// Skew-symmetric matrix [v x] such that skew(a) * b = a x b.
Eigen::Matrix3d skew(const Eigen::Vector3d& v);
/// SO(3) exponential: rotation matrix of the rotation vector phi [rad] (Rodrigues; exact near 0 and pi).
Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi);
/// SO(3) logarithm: rotation vector [rad] with |phi| <= pi of a rotation matrix.
Eigen::Vector3d so3_log(const Eigen::Matrix3d& R);
/// Unit Hamilton quaternion of the rotation vector phi [rad].
Eigen::Quaterniond quat_exp(const Eigen::Vector3d& phi);
/// Rotation vector [rad] (|phi| <= pi) of a unit Hamilton quaternion.
Eigen::Vector3d quat_log(const Eigen::Quaterniond& q);
/// Right Jacobian of SO(3) at phi (Forster et al. 2017 eq. 8).
Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi);
/// R_n_b from roll, pitch, yaw [rad] (aerospace z-y-x sequence: R_n_b = Rz(yaw) Ry(pitch) Rx(roll)).
Eigen::Matrix3d R_n_b_from_euler(double roll, double pitch, double yaw);
/// Roll, pitch, yaw [rad] of R_n_b (yaw in (-pi, pi]); at pitch = +-90 deg roll is set to 0.
Eigen::Vector3d euler_from_R_n_b(const Eigen::Matrix3d& R_n_b);
/// Nearest rotation matrix (SVD orthonormalization) to a nearly orthonormal matrix.
Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M);
/// Wrap an angle [rad] into (-pi, pi].
double wrap_pi(double angle);

}  // namespace pednav
