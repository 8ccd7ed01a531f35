// SPDX-License-Identifier: BSD-2-Clause
// Pieces shared by the GNSS-only kinematic filters (fusion/rtk_filter, fusion/tdcp_filter): the white-acceleration
// prediction of the antenna position and velocity (docs/carrier.md eq. 4.1), the median used to restart the white
// clock states, and a constellation's clock slot.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "gnss/types.hpp"

namespace pednav::fusion {

/// p += v Δt on states 0..2 (position) and 3..5 (velocity), every other state constant; P = Φ P Φᵀ + Q with the
/// white-acceleration Q of eq. 4.1 (√PSD sigma_h on the local horizontal axes, sigma_v on the vertical) [m/s²/√Hz].
void predict_white_acceleration(Eigen::VectorXd& x, Eigen::MatrixXd& P, double dt_s, double sigma_h, double sigma_v);

/// Median of v (0 when empty).
double median_of(std::vector<double> v);

/// Index of constellation s in `systems` (−1 when not configured).
int system_slot(const std::vector<gnss::System>& systems, gnss::System s);

}  // namespace pednav::fusion
