// SPDX-License-Identifier: BSD-2-Clause
// The antenna states of the tight coupling (fusion/antenna_state.hpp, docs/carrier.md §10).
#include "fusion/antenna_state.hpp"

#include <algorithm>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "gnss/least_squares.hpp"

#include <Eigen/Cholesky>

namespace pednav::fusion {

using Eigen::Matrix3d;
using Eigen::Vector3d;

AntennaTieRows antenna_tie_rows(const Vector3d& p_e, const Vector3d& v_e, const LeverArm& arm,
                                const Matrix3d& d_arm_d_b_e, const std::optional<Vector3d>& v_stride_e,
                                const Vector3d& ant_p_e, const Vector3d& ant_v_e, const Matrix3d& C_pos_e,
                                const Matrix3d& C_vel_e) {
  AntennaTieRows t;
  const Matrix3d I = Matrix3d::Identity();
  t.residual.head<3>() = -((ant_p_e - p_e) - arm.arm_e);
  t.J.block<3, 3>(0, kTieFootPos) = -I;
  t.J.block<3, 3>(0, kTieFootAtt) = -arm.d_arm_d_phi_e;
  t.J.block<3, 3>(0, kTieAntPos) = I;
  t.J.block<3, 3>(0, kTieArmError) = -d_arm_d_b_e;
  if (v_stride_e) {
    t.residual.tail<3>() = -(ant_v_e - *v_stride_e);
    t.J.block<3, 3>(3, kTieFootAtt) = -stride_velocity_attitude_jacobian(*v_stride_e);  // eq. 13.2
  } else {
    t.residual.tail<3>() = -(ant_v_e - v_e);
    t.J.block<3, 3>(3, kTieFootVel) = -I;
  }
  t.J.block<3, 3>(3, kTieAntVel) = I;
  t.cov_meas.topLeftCorner<3, 3>() = C_pos_e;
  t.cov_meas.bottomRightCorner<3, 3>() = C_vel_e;
  return t;
}

namespace {
Matrix3d level_cov_e(const Vector3d& p_e, double sigma_h, double sigma_v) {
  const Geodetic llh = geodetic_from_ecef(p_e);
  const Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  return Ren * Vector3d(sigma_h * sigma_h, sigma_h * sigma_h, sigma_v * sigma_v).asDiagonal() * Ren.transpose();
}
}  // namespace

Matrix3d antenna_position_cov_e(const EngineOptions& o, const Vector3d& p_e, bool mid_stance) {
  return mid_stance ? level_cov_e(p_e, o.antenna_stance_sigma_horizontal_m, o.antenna_stance_sigma_vertical_m)
                    : level_cov_e(p_e, o.antenna_sigma_horizontal_m, o.antenna_sigma_vertical_m);
}

std::vector<size_t> antenna_tie_samples(const std::vector<ins::ZuptDecision>& decisions,
                                        const std::vector<ins::ImuSample>& imu) {
  std::vector<size_t> out;
  const size_t n = std::min(decisions.size(), imu.size());
  for (size_t i = 0; i < n;) {
    if (!decisions[i].stance) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j < n && decisions[j].stance) ++j;
    const double span_s = imu[j - 1].t - imu[i].t;
    if (span_s < 2.0) {
      out.push_back((i + j - 1) / 2);
    } else {
      double next_s = 0.5;  // since the stance's first sample
      for (size_t k = i; k < j && imu[j - 1].t - imu[k].t >= 0.5; ++k) {
        if (imu[k].t - imu[i].t >= next_s) {
          out.push_back(k);
          next_s += kStandingTieSpacingS;
        }
      }
    }
    i = j;
  }
  return out;
}

Matrix3d antenna_velocity_cov_e(const EngineOptions& o, const Vector3d& p_e, bool stride) {
  return stride ? level_cov_e(p_e, o.antenna_stride_velocity_sigma_horizontal_mps,
                              o.antenna_stride_velocity_sigma_vertical_mps)
                : level_cov_e(p_e, o.antenna_velocity_sigma_horizontal_mps, o.antenna_velocity_sigma_vertical_mps);
}

Matrix3d arm_heading_axes_e(const Matrix3d& R_e_n, const Matrix3d& R_e_b) {
  Matrix3d D;
  for (int k = 0; k < 3; ++k) D.col(k) = lever_arm_e(Vector3d::Zero(), Vector3d::Unit(k), R_e_n, R_e_b).arm_e;
  return D;
}

LeverArm filter_lever_arm(const ErrorStateFilter& f, const EngineOptions& o) {
  const Geodetic llh = geodetic_from_ecef(f.x().nav.p_eb_e);
  const Vector3d arm_h = o.lever_arm_heading_m + (f.has_antenna() ? f.antenna_arm_error_h() : Vector3d::Zero());
  return lever_arm_e(o.lever_arm_n_m, arm_h, R_e_n(llh.lat, llh.lon), f.x().nav.R_e_b());
}

void init_antenna_from_foot(ErrorStateFilter& f, const EngineOptions& o, const StrideVelocity& stride) {
  if (!f.has_antenna()) return;
  const Vector3d& p = f.x().nav.p_eb_e;
  const LeverArm arm = filter_lever_arm(f, o);
  const std::optional<Vector3d> vs = stride.velocity_e();
  const Matrix3d cov_p = f.P().block<3, 3>(ins::kPos.offset, ins::kPos.offset) + antenna_position_cov_e(o, p);
  const Matrix3d cov_v =
      f.P().block<3, 3>(ins::kVel.offset, ins::kVel.offset) + antenna_velocity_cov_e(o, p, vs.has_value());
  // The arm's error: what the configured arm's σ (antenna_sigma_*) says about the arm a user measured or took as given.
  const double sh = o.antenna_sigma_horizontal_m, sv = o.antenna_sigma_vertical_m;
  f.init_antenna(p + arm.arm_e, vs.value_or(f.x().nav.v_eb_e), cov_p, cov_v, Vector3d(sh * sh, sh * sh, sv * sv).asDiagonal());
}

bool antenna_tie_update(ErrorStateFilter& f, const EngineOptions& o, const StrideVelocity& stride, bool mid_stance,
                        EngineSummary& sum) {
  if (!f.has_antenna()) return false;
  const Vector3d& p = f.x().nav.p_eb_e;
  const std::optional<Vector3d> vs = stride.velocity_e();
  const Geodetic llh = geodetic_from_ecef(p);
  const AntennaTieRows t = antenna_tie_rows(
      p, f.x().nav.v_eb_e, filter_lever_arm(f, o), arm_heading_axes_e(R_e_n(llh.lat, llh.lon), f.x().nav.R_e_b()), vs,
      f.antenna_p_e(), f.antenna_v_e(), antenna_position_cov_e(o, p, mid_stance),
      antenna_velocity_cov_e(o, p, vs.has_value()));
  const int n = f.layout().dim(), a = f.antenna_offset();
  Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor, 6, ins::kMaxErrorDim> H =
      Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor, 6, ins::kMaxErrorDim>::Zero(6, n);
  H.middleCols<3>(ins::kPos.offset) = t.J.middleCols<3>(kTieFootPos);
  H.middleCols<3>(ins::kVel.offset) = t.J.middleCols<3>(kTieFootVel);
  H.middleCols<3>(ins::kAtt.offset) = t.J.middleCols<3>(kTieFootAtt);
  H.middleCols<3>(a) = t.J.middleCols<3>(kTieAntPos);
  H.middleCols<3>(a + 3) = t.J.middleCols<3>(kTieAntVel);
  H.middleCols<3>(a + 6) = t.J.middleCols<3>(kTieArmError);
  // Eq. 10.4: each half's d² = rᵀ S⁻¹ r against χ²(3); beyond it the half's noise is inflated by d²/χ² (the foot
  // and the antenna disagree beyond both σ's: the tie still holds them together, as loosely as the data say).
  const double gate = gnss::chi_square_quantile(o.fault_probability, 3);
  Eigen::Matrix<double, 6, 6> R = t.cov_meas;
  for (int half = 0; half < 2; ++half) {
    const auto Hh = H.middleRows<3>(3 * half);
    const Matrix3d S = Hh * f.P() * Hh.transpose() + t.cov_meas.block<3, 3>(3 * half, 3 * half);
    const Vector3d r = t.residual.segment<3>(3 * half);
    const Eigen::LDLT<Matrix3d> ldlt(S);
    const double d2 = ldlt.info() == Eigen::Success ? r.dot(ldlt.solve(r)) : 0.0;
    if (d2 <= gate) {
      ++sum.carrier.antenna_ties;
    } else {
      ++sum.carrier.antenna_ties_inflated;
      R.block<3, 3>(3 * half, 3 * half) *= d2 / gate;
    }
  }
  return f.update(t.residual, H, R);
}

}  // namespace pednav::fusion
