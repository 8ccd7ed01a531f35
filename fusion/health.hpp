// SPDX-License-Identifier: BSD-2-Clause
// Covariance health check of the forward engine (docs/robustness.md "Filter health"): a covariance that lost its
// symmetry or positive semi-definiteness means the filter's idea of its own accuracy is broken (divergence), even
// while the state still looks plausible. Fixed-capacity matrices: nothing is allocated.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>

#include "ins/error_state.hpp"

namespace pednav::fusion {

/// P is symmetrized after every prediction and update, so an asymmetry above this fraction of its largest entry is a
/// defect (rounding leaves ~1e-16).
inline constexpr double kMaxRelativeAsymmetry = 1e-9;
/// Smallest admissible LDLT pivot of the correlation matrix D^-1/2 P D^-1/2 (unitless: states of different units
/// weigh alike); below −this, P is not positive semi-definite.
inline constexpr double kMinCorrelationPivot = 1e-6;

/// Why the error covariance P [state units²] is unusable: nullptr if it is finite, symmetric and positive
/// semi-definite, else a short reason ("covariance not symmetric", ...).
inline const char* covariance_defect(const ins::ErrorMatrix& P) {
  if (!P.allFinite()) return "non-finite covariance";
  if (P.rows() == 0) return nullptr;
  for (int i = 0; i < P.rows(); ++i) {
    if (P(i, i) < 0.0) return "negative variance";
  }
  const double scale = P.cwiseAbs().maxCoeff();
  if (scale > 0.0 && (P - P.transpose()).cwiseAbs().maxCoeff() > kMaxRelativeAsymmetry * scale) {
    return "covariance not symmetric";
  }
  ins::ErrorVector inv_sd(P.rows());
  for (int i = 0; i < P.rows(); ++i) inv_sd(i) = P(i, i) > 0.0 ? 1.0 / std::sqrt(P(i, i)) : 0.0;
  const ins::ErrorMatrix C = inv_sd.asDiagonal() * P * inv_sd.asDiagonal();
  const Eigen::LDLT<ins::ErrorMatrix> ldlt(C);
  if (ldlt.info() != Eigen::Success || ldlt.vectorD().minCoeff() < -kMinCorrelationPivot) {
    return "covariance not positive semi-definite";
  }
  return nullptr;
}

}  // namespace pednav::fusion
