// SPDX-License-Identifier: BSD-2-Clause
#include "core/rotation.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"

namespace pednav {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi) {
  const double a2 = phi.squaredNorm();
  const double a = std::sqrt(a2);
  const Eigen::Matrix3d k = skew(phi);
  double s, c;  // sin(a)/a and (1-cos a)/a^2, series below 1e-4 rad
  if (a < 1e-4) {
    s = 1.0 - a2 / 6.0 + a2 * a2 / 120.0;
    c = 0.5 - a2 / 24.0 + a2 * a2 / 720.0;
  } else {
    s = std::sin(a) / a;
    c = (1.0 - std::cos(a)) / a2;
  }
  return Eigen::Matrix3d::Identity() + s * k + c * k * k;
}

Eigen::Vector3d quat_log(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest rotation: angle <= pi
  const Eigen::Vector3d v = q.vec();
  const double sn = v.norm();
  if (sn < 1e-8) {
    // 2 atan2(sn, w)/sn ~ 2/w (1 - sn^2/(3 w^2))
    return (2.0 / q.w()) * (1.0 - sn * sn / (3.0 * q.w() * q.w())) * v;
  }
  const double angle = 2.0 * std::atan2(sn, q.w());
  return (angle / sn) * v;
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) { return quat_log(Eigen::Quaterniond(R)); }

Eigen::Quaterniond quat_exp(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const double half = 0.5 * a;
  const double k = (a < 1e-6) ? 0.5 - a * a / 48.0 : std::sin(half) / a;
  return Eigen::Quaterniond(std::cos(half), k * phi.x(), k * phi.y(), k * phi.z());
}

Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi) {
  const double a2 = phi.squaredNorm();
  const double a = std::sqrt(a2);
  const Eigen::Matrix3d k = skew(phi);
  if (a < 1e-4) return Eigen::Matrix3d::Identity() - 0.5 * k + k * k / 6.0;
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(a)) / a2 * k + (a - std::sin(a)) / (a2 * a) * k * k;
}

Eigen::Matrix3d R_n_b_from_euler(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d euler_from_R_n_b(const Eigen::Matrix3d& R) {
  const double sp = std::clamp(-R(2, 0), -1.0, 1.0);
  const double pitch = std::asin(sp);
  double roll, yaw;
  if (std::abs(sp) > 1.0 - 1e-12) {
    roll = 0.0;
    yaw = std::atan2(-R(0, 1), R(1, 1));
  } else {
    roll = std::atan2(R(2, 1), R(2, 2));
    yaw = std::atan2(R(1, 0), R(0, 0));
  }
  return {roll, pitch, wrap_pi(yaw)};
}

Eigen::Matrix3d orthonormalize(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0.0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) = -u.col(2);
    r = u * svd.matrixV().transpose();
  }
  return r;
}

double wrap_pi(double angle) {
  double a = std::remainder(angle, 2.0 * kPi);
  if (a <= -kPi) a += 2.0 * kPi;
  return a;
}

}  // namespace pednav
