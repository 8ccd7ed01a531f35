// SPDX-License-Identifier: BSD-2-Clause
// LAMBDA through RTKLIB (gnss/rtklib/lambda.hpp).
#include "gnss/rtklib/lambda.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <vector>

#include "gnss/rtklib/rtklib_c.hpp"

namespace pednav::gnss {

double bootstrapped_success_rate(const Eigen::MatrixXd& Q) {
  const Eigen::LLT<Eigen::MatrixXd> llt(Q);
  if (llt.info() != Eigen::Success) return 0.0;
  // Q = L Lᵀ: the conditional standard deviations of the sequential (bootstrapping) order are L's diagonal.
  const Eigen::MatrixXd L = llt.matrixL();
  double p = 1.0;
  for (Eigen::Index i = 0; i < Q.rows(); ++i) p *= std::erf(1.0 / (2.0 * std::sqrt(2.0) * L(i, i)));  // 2Φ(x) − 1 = erf(x/√2)
  return p;
}

Expected<IntegerSolution> integer_least_squares(const Eigen::VectorXd& a, const Eigen::MatrixXd& Q_a) {
  const int n = static_cast<int>(a.size());
  if (n < 1 || Q_a.rows() != n || Q_a.cols() != n) return make_error("integer_least_squares: size mismatch");
  if (!a.allFinite() || !Q_a.allFinite()) return make_error("integer_least_squares: non-finite float ambiguities");
  const Eigen::MatrixXd Qs = 0.5 * (Q_a + Q_a.transpose());
  if (Eigen::LLT<Eigen::MatrixXd>(Qs).info() != Eigen::Success) {
    return make_error("integer_least_squares: the ambiguity covariance is not positive definite");
  }
  constexpr int kCandidates = 2;
  std::vector<double> F(static_cast<size_t>(n) * kCandidates), s(kCandidates);
  // RTKLIB matrices are column-major double arrays, like Eigen's default.
  if (lambda(n, kCandidates, a.data(), Qs.data(), F.data(), s.data()) != 0) {
    return make_error("integer_least_squares: LAMBDA search failed");
  }
  IntegerSolution out;
  out.best = Eigen::Map<const Eigen::VectorXd>(F.data(), n);
  out.second = Eigen::Map<const Eigen::VectorXd>(F.data() + n, n);
  out.norm_best = s[0];
  out.norm_second = s[1];
  // The success rate of the decorrelated problem Z Q Zᵀ (lambda_reduction returns Z, n × n, column-major).
  std::vector<double> Z(static_cast<size_t>(n) * n);
  if (lambda_reduction(n, Qs.data(), Z.data()) == 0) {
    const Eigen::Map<const Eigen::MatrixXd> Zm(Z.data(), n, n);
    out.success_rate = bootstrapped_success_rate(Zm.transpose() * Qs * Zm);
  } else {
    out.success_rate = bootstrapped_success_rate(Qs);
  }
  return out;
}

}  // namespace pednav::gnss
