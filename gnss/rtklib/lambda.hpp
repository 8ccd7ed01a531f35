// SPDX-License-Identifier: BSD-2-Clause
// Integer least squares by LAMBDA (Teunissen 1995), through RTKLIB's lambda() and lambda_reduction() (Debian's
// libRTKLib). Pure computation: no RTKLIB globals are touched, so it may run on any thread.
#pragma once

#include <Eigen/Core>

#include "core/expected.hpp"

namespace pednav::gnss {

/// The two best integer vectors of the float vector a [cycles] with covariance Q_a [cycles²] in the metric of
/// Q_a⁻¹, their squared norms (a − z)ᵀ Q_a⁻¹ (a − z), and the bootstrapped success rate of the decorrelated problem
/// (a lower bound of the ILS success rate, Teunissen 1999; docs/carrier.md eq. 3.4).
struct IntegerSolution {
  Eigen::VectorXd best, second;
  double norm_best = 0.0, norm_second = 0.0;
  double ratio() const { return norm_best > 0.0 ? norm_second / norm_best : 1e9; }
  double success_rate = 0.0;
};

/// LAMBDA search for a (n ≥ 1) with covariance Q_a (n × n, symmetric positive definite). Fails with a message when
/// Q_a is not positive definite or RTKLIB's search fails.
Expected<IntegerSolution> integer_least_squares(const Eigen::VectorXd& a, const Eigen::MatrixXd& Q_a);

/// Bootstrapped success rate Π_i (2Φ(1 / (2 σ_i|I)) − 1) of a covariance whose conditional variances σ²_i|I are
/// those of its LDLᵀ factorization (docs/carrier.md eq. 3.4); 0 when Q is not positive definite.
double bootstrapped_success_rate(const Eigen::MatrixXd& Q);

}  // namespace pednav::gnss
