// SPDX-License-Identifier: BSD-2-Clause
// ZUPT, ZARU and step-velocity updates (fusion/stance_updates.hpp).
#include "fusion/stance_updates.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "gnss/least_squares.hpp"

namespace pednav::fusion {

using Eigen::Vector3d;

namespace {
constexpr double kChi2Dof3P99 = 11.3449;  // χ²(3) 99 % quantile
}  // namespace

Eigen::Matrix<double, 3, 6> zupt_jacobian(const Eigen::Vector3d& v_e, ZuptForm form) {
  // Error state: v_true = v_est + δv, R_true = exp([φ×]) R_est (docs/error_state.md). The velocity error that an
  // attitude error alone produces is φ × v̂ = -[v̂×]φ; the dynamic error (seed 001 eq. 5) is δv_dyn = δv + [v̂×]φ,
  // and form D measures it (seed 001 eq. 8): H = [I, [v̂×]]. Form F measures δv itself: H = [I, 0].
  Eigen::Matrix<double, 3, 6> J = Eigen::Matrix<double, 3, 6>::Zero();
  J.leftCols<3>().setIdentity();
  if (form == ZuptForm::kDynamic) J.rightCols<3>() = skew(v_e);
  return J;
}

StanceUpdater::StanceUpdater(const EngineOptions& o)
    : o_(o),
      zaru_gate_threshold_(o.zaru_gate_probability > 0.0 ? gnss::chi_square_quantile(o.zaru_gate_probability, 3) : 0.0) {}

void StanceUpdater::zupt_update(ErrorStateFilter& f, const ins::ImuIncrement& inc, bool interval_start_stance, EngineSummary& sum) {
  const int n = f.layout().dim();
  const Vector3d v = f.x().nav.v_eb_e;
  bool zaru = o_.zaru && interval_start_stance && inc.dt_s > 0.0;
  Vector3d r_zaru = Vector3d::Zero();
  Rows3 H_zaru;
  if (zaru) {
    H_zaru = zaru_rows(f, inc, r_zaru);
    if (zaru_gate_threshold_ > 0.0 && !zaru_passes_gate(f, H_zaru, r_zaru, zaru_variance(inc))) {
      zaru = false;
      ++sum.zaru_rejected;
    }
  }
  sum.zaru_updates += zaru;
  const int m = zaru ? 6 : 3;
  // Fixed capacity (6 rows): no heap allocation.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, ins::kMaxErrorDim> H =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, ins::kMaxErrorDim>::Zero(m, n);
  Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 6, 1> r(m);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6> R =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6>::Zero(m, m);
  const Eigen::Matrix<double, 3, 6> J = zupt_jacobian(v, o_.zupt_form);
  H.block<3, 3>(0, ins::kVel.offset) = J.leftCols<3>();
  H.block<3, 3>(0, ins::kAtt.offset) = J.rightCols<3>();
  r.head<3>() = -v;
  R.topLeftCorner<3, 3>().diagonal().setConstant(o_.zupt_sigma_mps * o_.zupt_sigma_mps);
  if (zaru) {
    H.middleRows<3>(3) = H_zaru;
    r.tail<3>() = r_zaru;
    R.bottomRightCorner<3, 3>().diagonal().setConstant(zaru_variance(inc));
  }
  // The velocity rows' NIS against χ²(3) before the update (docs/fusion.md §15): the run's zupt_innovations check.
  {
    // H's velocity rows touch velocity and attitude only (J above): S from their 6 × 6 block, no allocation.
    const int iv = ins::kVel.offset, ia = ins::kAtt.offset;
    Eigen::Matrix<double, 6, 6> Pva;
    Pva << f.P().block<3, 3>(iv, iv), f.P().block<3, 3>(iv, ia), f.P().block<3, 3>(ia, iv), f.P().block<3, 3>(ia, ia);
    const Eigen::Matrix3d S = J * Pva * J.transpose() + R.topLeftCorner<3, 3>();
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(S);
    if (ldlt.info() == Eigen::Success) {
      const double nis = r.head<3>().dot(ldlt.solve(r.head<3>()));
      sum.zupt_nis_sum += nis;
      sum.zupt_nis_above_p99 += nis > kChi2Dof3P99;
      if (!interval_start_stance) {
        ++sum.zupt_first_of_stance;
        sum.zupt_first_nis_sum += nis;
        sum.zupt_first_nis_above_p99 += nis > kChi2Dof3P99;
      }
    }
  }
  const Vector3d v_before = v;
  if (!f.update(r, H, R)) return;
  if (o_.zupt_form == ZuptForm::kDynamic) {
    // The error state is kept in the dynamic-error sense only through v̂; the update moved v̂, so re-express the
    // covariance at the new v̂: P <- J P J^T, J = I + E_v [(v̂- - v̂+)x] E_φ^T (docs/fusion.md eq. 5.9). Without it
    // the velocity-yaw correlation left by the swing makes the following stance ZUPTs act like form F.
    f.reexpress_velocity_attitude(skew(v_before - f.x().nav.v_eb_e));
  }
}

Rows3 StanceUpdater::zaru_rows(const ErrorStateFilter& f, const ins::ImuIncrement& inc, Vector3d& r) const {
  Rows3 H = Rows3::Zero(3, f.layout().dim());
  const Vector3d omega_ie_b = f.x().nav.R_e_b().transpose() * Vector3d(0, 0, wgs84::kOmegaIE_radps);
  r = inc.alpha_b / inc.dt_s - omega_ie_b;  // = true - estimated bias if the foot is still
  H.block<3, 3>(0, ins::kBiasGyro.offset).setIdentity();
  // The g-sensitive part δG_g f of the corrected rate (docs/error_state.md eq. 5.4): without it the ZARU would
  // tell the bias apart from G_g f at rest, and the tilt drift the ZUPTs see would then "observe" G_g.
  if (const int g = f.g_sensitivity_offset(); g >= 0) {
    const Vector3d f_b = inc.upsilon_b / inc.dt_s;
    for (int j = 0; j < 3; ++j) H.block<3, 3>(0, g + 3 * j).diagonal().setConstant(f_b(j));
  }
  return H;
}

double StanceUpdater::zaru_variance(const ins::ImuIncrement& inc) const {
  return o_.zaru_sigma_radps * o_.zaru_sigma_radps / std::max(1, inc.samples);
}

bool StanceUpdater::zaru_passes_gate(const ErrorStateFilter& f, const Rows3& H, const Vector3d& r, double variance) const {
  Eigen::Matrix3d S = H * f.P() * H.transpose();
  S.diagonal().array() += variance;
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(S);
  if (ldlt.info() != Eigen::Success) return false;
  const double d2 = r.dot(ldlt.solve(r));
  return std::isfinite(d2) && d2 <= zaru_gate_threshold_;
}

void StanceUpdater::step_velocity_update(ErrorStateFilter& f, const StepMeasurement& m, EngineSummary& sum) {
  const StepVelocityRows rows = step_velocity_rows(f.x().nav, m, o_.step_velocity);
  Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, ins::kMaxErrorDim> H =
      Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, ins::kMaxErrorDim>::Zero(3, f.layout().dim());
  H.block<3, 3>(0, ins::kVel.offset) = rows.J_dv_phi.leftCols<3>();
  H.block<3, 3>(0, ins::kAtt.offset) = rows.J_dv_phi.rightCols<3>();
  if (f.update(rows.residual, H, rows.cov_meas)) ++sum.step_velocity_updates;
}
HandNhcRows hand_nhc_rows(const ins::NavState& nav, double sigma_cross_mps, double sigma_up_mps) {
  StepMeasurement m;
  m.mean_v_e = nav.v_eb_e;  // the current velocity: the step model's ∂h/∂δv is exact here
  StepVelocityOptions so;
  so.sigma_cross_mps = sigma_cross_mps;
  so.sigma_vertical_mps = sigma_up_mps;
  const StepVelocityRows step = step_velocity_rows(nav, m, so);
  HandNhcRows rows;
  rows.residual = step.residual.tail<2>();
  rows.J_dv_phi = step.J_dv_phi.bottomRows<2>();
  rows.cov_meas = step.cov_meas.bottomRightCorner<2, 2>();
  return rows;
}

bool StanceUpdater::hand_nhc_update(ErrorStateFilter& f, double sigma_cross_mps, double sigma_up_mps) {
  const HandNhcRows rows = hand_nhc_rows(f.x().nav, sigma_cross_mps, sigma_up_mps);
  Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::ColMajor, 2, ins::kMaxErrorDim> H =
      Eigen::Matrix<double, 2, Eigen::Dynamic, Eigen::ColMajor, 2, ins::kMaxErrorDim>::Zero(2, f.layout().dim());
  H.block<2, 3>(0, ins::kVel.offset) = rows.J_dv_phi.leftCols<3>();
  H.block<2, 3>(0, ins::kAtt.offset) = rows.J_dv_phi.rightCols<3>();
  return f.update(rows.residual, H, rows.cov_meas);
}

}  // namespace pednav::fusion
