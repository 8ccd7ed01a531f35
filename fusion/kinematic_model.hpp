// SPDX-License-Identifier: BSD-2-Clause
// Pieces shared by the GNSS-only kinematic filters (fusion/rtk_filter, fusion/tdcp_filter): the white-acceleration
// prediction of the antenna position and velocity (docs/carrier.md eq. 4.1), the median used to restart the white
// clock states, and a constellation's clock slot.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "gnss/types.hpp"

namespace pednav::fusion {

/// p += v Δt on states 0..2 (position) and 3..5 (velocity), every other state constant; P = Φ P Φᵀ + Q with the
/// white-acceleration Q of eq. 4.1 (√PSD sigma_h on the local horizontal axes, sigma_v on the vertical) [m/s²/√Hz].
void predict_white_acceleration(Eigen::VectorXd& x, Eigen::MatrixXd& P, double dt_s, double sigma_h, double sigma_v);

/// One pass of the w-test update of eq. 4.5 over the active rows (each with `active`, `h`, `residual`, `sigma`):
/// act = their indices, H, r, R (variances) stacked, PHt = P Hᵀ, S = H P Hᵀ + diag R and Sinv = S⁻¹. False when S
/// is not positive definite (LDLT fails).
struct WTestPass {
  std::vector<int> act;
  Eigen::MatrixXd H, PHt, Sinv;
  Eigen::VectorXd r, R;
};
bool w_test_pass_solve(const Eigen::MatrixXd& P, WTestPass& pass);
/// The active row (index into pass.act) with the largest w = |(S⁻¹r)_i| / √(S⁻¹)_ii above w_crit, skipping those
/// skip(row index) marks; −1 when none is above.
template <typename Skip>
int w_test_worst(const WTestPass& pass, double w_crit, Skip skip) {
  const Eigen::VectorXd t = pass.Sinv * pass.r;
  int worst = -1;
  double worst_w = w_crit;
  for (int i = 0; i < static_cast<int>(pass.act.size()); ++i) {
    if (skip(pass.act[i])) continue;
    const double w = std::abs(t(i)) / std::sqrt(pass.Sinv(i, i));
    if (w > worst_w) worst_w = w, worst = i;
  }
  return worst;
}
template <typename Row>
bool w_test_pass(const std::vector<Row>& rows, const Eigen::MatrixXd& P, WTestPass& pass) {
  pass.act.clear();
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].active) pass.act.push_back(static_cast<int>(i));
  }
  const int m = static_cast<int>(pass.act.size());
  pass.H.resize(m, P.cols());
  pass.r.resize(m);
  pass.R.resize(m);
  for (int i = 0; i < m; ++i) {
    const Row& row = rows[pass.act[i]];
    pass.H.row(i) = row.h;
    pass.r(i) = row.residual;
    pass.R(i) = row.sigma * row.sigma;
  }
  return w_test_pass_solve(P, pass);
}

/// The Kalman update of a pass that no row failed: K = P Hᵀ S⁻¹, dx = K r, Joseph form P_post = (I − K H) P (I − K H)ᵀ
/// + K R Kᵀ.
void joseph_update(const Eigen::MatrixXd& P, const WTestPass& pass, Eigen::VectorXd& dx, Eigen::MatrixXd& P_post);

/// Median of v (0 when empty).
double median_of(std::vector<double> v);

/// Index of constellation s in `systems` (−1 when not configured).
int system_slot(const std::vector<gnss::System>& systems, gnss::System s);

}  // namespace pednav::fusion
