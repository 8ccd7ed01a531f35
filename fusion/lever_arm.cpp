// SPDX-License-Identifier: BSD-2-Clause
#include "fusion/lever_arm.hpp"

#include <cmath>

namespace pednav::fusion {

LeverArm lever_arm_e(const Eigen::Vector3d& arm_n_m, const Eigen::Vector3d& arm_heading_m, const Eigen::Matrix3d& R_e_n,
                     const Eigen::Matrix3d& R_e_b) {
  LeverArm out;
  Eigen::Vector3d arm_n = arm_n_m;
  if (!arm_heading_m.isZero()) {
    const Eigen::Vector3d x_n = R_e_n.transpose() * R_e_b.col(0);  // the foot's x axis in NED
    const double h2 = x_n.x() * x_n.x() + x_n.y() * x_n.y();
    if (h2 > 1e-12) {
      const double h = std::sqrt(h2);
      const Eigen::Vector3d u_f(x_n.x() / h, x_n.y() / h, 0.0);
      const Eigen::Vector3d u_r(-x_n.y() / h, x_n.x() / h, 0.0);
      const double l_f = arm_heading_m.x(), l_r = arm_heading_m.y(), l_d = arm_heading_m.z();
      arm_n += l_f * u_f + l_r * u_r + Eigen::Vector3d(0.0, 0.0, l_d);  // eq. 14.1
      // Eq. 14.2: δarm_n = (∂arm_n/∂ψ) (∂ψ/∂φ_n) φ_n, φ_n = R_e_nᵀ φ_e.
      const Eigen::Vector3d d_arm_d_psi = l_f * u_r - l_r * u_f;
      const Eigen::RowVector3d d_psi_d_phi_n(-x_n.z() * x_n.x() / h2, -x_n.z() * x_n.y() / h2, 1.0);
      out.d_arm_d_phi_e = R_e_n * (d_arm_d_psi * d_psi_d_phi_n) * R_e_n.transpose();
    }
  }
  out.arm_e = R_e_n * arm_n;
  return out;
}

}  // namespace pednav::fusion
