// SPDX-License-Identifier: BSD-2-Clause
// Central-difference Jacobians for checking analytic ones.
#pragma once

#include <Eigen/Core>
#include <functional>

namespace pednav::test {

/// J = d f(x) / d x by central differences with step h (per component).
inline Eigen::MatrixXd numerical_jacobian(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                          const Eigen::VectorXd& x, double h) {
  const Eigen::VectorXd f0 = f(x);
  Eigen::MatrixXd J(f0.size(), x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += h;
    xm(i) -= h;
    J.col(i) = (f(xp) - f(xm)) / (2.0 * h);
  }
  return J;
}

}  // namespace pednav::test
