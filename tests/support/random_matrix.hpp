// SPDX-License-Identifier: BSD-2-Clause
// Random test matrices shared by the filter and smoother tests.
#pragma once

#include <Eigen/Dense>
#include <random>

namespace pednav::test {

/// A random symmetric positive-definite n × n matrix: scale · (L Lᵀ / n + 0.2 I), L with standard normal entries.
inline Eigen::MatrixXd random_spd(std::mt19937& rng, int n, double scale) {
  std::normal_distribution<double> nd(0.0, 1.0);
  Eigen::MatrixXd L(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) L(i, j) = nd(rng);
  }
  return scale * (L * L.transpose() / n + 0.2 * Eigen::MatrixXd::Identity(n, n));
}

}  // namespace pednav::test
