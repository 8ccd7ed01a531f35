// SPDX-License-Identifier: BSD-2-Clause
#include "ins/gravity.hpp"

#include "core/geodesy.hpp"
#include "core/rotation.hpp"

namespace pednav::ins {

// Groves 2013 eq. 2.142: γ = -GM/r³ { r + 3/2 J2 (a/r)² [ (1 - 5 z²/r²) x, (1 - 5 z²/r²) y, (3 - 5 z²/r²) z ] }.
Eigen::Vector3d gravitation_ecef(const Eigen::Vector3d& p_e) {
  const double r2 = p_e.squaredNorm();
  const double r = std::sqrt(r2);
  const double zr2 = p_e.z() * p_e.z() / r2;
  const double k = 1.5 * wgs84::kJ2 * wgs84::kA_m * wgs84::kA_m / r2;
  const double gm_r3 = wgs84::kGM_m3ps2 / (r2 * r);
  return -gm_r3 * Eigen::Vector3d((1.0 + k * (1.0 - 5.0 * zr2)) * p_e.x(), (1.0 + k * (1.0 - 5.0 * zr2)) * p_e.y(),
                                  (1.0 + k * (3.0 - 5.0 * zr2)) * p_e.z());
}

// Groves 2013 §2.4.7: g = γ - Ω_ie Ω_ie r  (Ω_ie = [ω_ie×], ω_ie = (0, 0, ω)).
Eigen::Vector3d gravity_ecef(const Eigen::Vector3d& p_e) {
  constexpr double w2 = wgs84::kOmegaIE_radps * wgs84::kOmegaIE_radps;
  return gravitation_ecef(p_e) + Eigen::Vector3d(w2 * p_e.x(), w2 * p_e.y(), 0.0);
}

Eigen::Matrix3d gravity_gradient_ecef(const Eigen::Vector3d& p_e) {
  const double r = p_e.norm();
  const Eigen::Vector3d u = p_e / r;
  constexpr double w2 = wgs84::kOmegaIE_radps * wgs84::kOmegaIE_radps;
  Eigen::Matrix3d G = -wgs84::kGM_m3ps2 / (r * r * r) * (Eigen::Matrix3d::Identity() - 3.0 * u * u.transpose());
  G(0, 0) += w2;
  G(1, 1) += w2;
  return G;
}

}  // namespace pednav::ins
