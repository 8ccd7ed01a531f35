// Error-state model (docs/error_state.md). State order: δp_e [0,3), δv_e [3,6), φ_e [6,9), δb_g [9,12),
// δb_a [12,15), then registered optional blocks. Noise order: n_g, n_a, w_bg, w_ba, (w_sg), (w_sa).
#include "ins/error_state.hpp"

#include <unsupported/Eigen/MatrixFunctions>

#include "core/column_sparse.hpp"
#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "ins/gravity.hpp"

namespace pednav::ins {
namespace {

const Eigen::Vector3d kOmegaIE_e(0.0, 0.0, wgs84::kOmegaIE_radps);

template <typename M>
auto blk(M& m, Block r, Block c) {
  return m.block(r.offset, c.offset, r.dim, c.dim);
}

}  // namespace

ErrorStateLayout::ErrorStateLayout() {
  blocks_ = {{"pos", kPos}, {"vel", kVel}, {"att", kAtt}, {"bias_gyro", kBiasGyro}, {"bias_acc", kBiasAcc}};
  dim_ = kCoreDim;
}

Expected<Block> ErrorStateLayout::add(const std::string& name, int dim) {
  if (dim < 1) return make_error("error state: block '" + name + "' must have dim >= 1, got " + std::to_string(dim));
  if (find(name)) return make_error("error state: block '" + name + "' is already registered");
  if (dim_ + dim > kMaxErrorDim) {
    return make_error("error state: block '" + name + "' would make " + std::to_string(dim_ + dim) +
                      " states, more than the " + std::to_string(kMaxErrorDim) + " the filter holds (kMaxErrorDim)");
  }
  const Block b{dim_, dim};
  blocks_.emplace_back(name, b);
  dim_ += dim;
  return b;
}

std::optional<Block> ErrorStateLayout::find(const std::string& name) const {
  for (const auto& [n, b] : blocks_) {
    if (n == name) return b;
  }
  return std::nullopt;
}

InsState boxplus(const InsState& x, const Eigen::Ref<const Eigen::VectorXd>& dx, const ErrorStateLayout& layout) {
  InsState y = x;
  y.nav.p_eb_e += dx.segment<3>(kPos.offset);
  y.nav.v_eb_e += dx.segment<3>(kVel.offset);
  y.nav.q_e_b = (quat_exp(dx.segment<3>(kAtt.offset)) * x.nav.q_e_b).normalized();  // R_true = exp([φ×]) R_est
  y.imu.b_g += dx.segment<3>(kBiasGyro.offset);
  y.imu.b_a += dx.segment<3>(kBiasAcc.offset);
  if (auto b = layout.find(kScaleGyroBlock)) y.imu.s_g += dx.segment<3>(b->offset);
  if (auto b = layout.find(kScaleAccBlock)) y.imu.s_a += dx.segment<3>(b->offset);
  return y;
}

Eigen::VectorXd boxminus(const InsState& a, const InsState& b, const ErrorStateLayout& layout) {
  Eigen::VectorXd dx = Eigen::VectorXd::Zero(layout.dim());
  dx.segment<3>(kPos.offset) = a.nav.p_eb_e - b.nav.p_eb_e;
  dx.segment<3>(kVel.offset) = a.nav.v_eb_e - b.nav.v_eb_e;
  dx.segment<3>(kAtt.offset) = quat_log(a.nav.q_e_b * b.nav.q_e_b.conjugate());
  dx.segment<3>(kBiasGyro.offset) = a.imu.b_g - b.imu.b_g;
  dx.segment<3>(kBiasAcc.offset) = a.imu.b_a - b.imu.b_a;
  if (auto s = layout.find(kScaleGyroBlock)) dx.segment<3>(s->offset) = a.imu.s_g - b.imu.s_g;
  if (auto s = layout.find(kScaleAccBlock)) dx.segment<3>(s->offset) = a.imu.s_a - b.imu.s_a;
  return dx;
}

// docs/error_state.md eq. (3.1)-(3.8):
//   δṗ = δv
//   δv̇ = Γ δp - 2[ω_ie×] δv - [f_e×] φ - R δb_a - R diag(f_b) δs_a - R n_a
//   φ̇  = -[ω_ie×] φ - R δb_g - R diag(ω_b) δs_g - R n_g
//   δḃ = -δb/τ + w_b  (τ <= 0: random walk),   δṡ = -δs/τ_s + w_s
ContinuousErrorModel continuous_error_model(const ErrorStateLayout& layout, const ImuSpec& spec,
                                            const Eigen::Matrix3d& R_e_b, const Eigen::Vector3d& p_eb_e,
                                            const Eigen::Vector3d& f_ib_b, const Eigen::Vector3d& omega_ib_b) {
  const int n = layout.dim();
  const auto sg = layout.find(kScaleGyroBlock);
  const auto sa = layout.find(kScaleAccBlock);
  const int nw = 12 + (sg ? 3 : 0) + (sa ? 3 : 0);
  const Block wNg{0, 3}, wNa{3, 3}, wBg{6, 3}, wBa{9, 3};
  ContinuousErrorModel m;
  m.F = ErrorMatrix::Zero(n, n);
  m.G = ErrorMatrix::Zero(n, nw);
  m.Q = ErrorMatrix::Zero(nw, nw);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d W = skew(kOmegaIE_e);
  const Eigen::Vector3d f_e = R_e_b * f_ib_b;

  blk(m.F, kPos, kVel) = I;
  blk(m.F, kVel, kPos) = gravity_gradient_ecef(p_eb_e);
  blk(m.F, kVel, kVel) = -2.0 * W;
  blk(m.F, kVel, kAtt) = -skew(f_e);
  blk(m.F, kVel, kBiasAcc) = -R_e_b;
  blk(m.F, kAtt, kAtt) = -W;
  blk(m.F, kAtt, kBiasGyro) = -R_e_b;
  if (spec.gyro_bias_tau_s > 0.0) blk(m.F, kBiasGyro, kBiasGyro) = -I / spec.gyro_bias_tau_s;
  if (spec.accel_bias_tau_s > 0.0) blk(m.F, kBiasAcc, kBiasAcc) = -I / spec.accel_bias_tau_s;

  blk(m.G, kVel, wNa) = -R_e_b;
  blk(m.G, kAtt, wNg) = -R_e_b;
  blk(m.G, kBiasGyro, wBg) = I;
  blk(m.G, kBiasAcc, wBa) = I;
  auto psd_gm = [](double sigma, double tau) { return tau > 0.0 ? 2.0 * sigma * sigma / tau : 0.0; };
  blk(m.Q, wNg, wNg) = spec.gyro_arw * spec.gyro_arw * I;
  blk(m.Q, wNa, wNa) = spec.accel_vrw * spec.accel_vrw * I;
  blk(m.Q, wBg, wBg) =
      (psd_gm(spec.gyro_bias_instability, spec.gyro_bias_tau_s) + spec.gyro_bias_rw * spec.gyro_bias_rw) * I;
  blk(m.Q, wBa, wBa) =
      (psd_gm(spec.accel_bias_instability, spec.accel_bias_tau_s) + spec.accel_bias_rw * spec.accel_bias_rw) * I;

  int w = 12;
  if (sg) {
    const Block s = *sg, ws{w, 3};
    blk(m.F, kAtt, s) = -R_e_b * omega_ib_b.asDiagonal();
    if (spec.scale_tau_s > 0.0) blk(m.F, s, s) = -I / spec.scale_tau_s;
    blk(m.G, s, ws) = I;
    blk(m.Q, ws, ws) = psd_gm(spec.gyro_scale_sigma, spec.scale_tau_s) * I;
    w += 3;
  }
  if (sa) {
    const Block s = *sa, ws{w, 3};
    blk(m.F, kVel, s) = -R_e_b * f_ib_b.asDiagonal();
    if (spec.scale_tau_s > 0.0) blk(m.F, s, s) = -I / spec.scale_tau_s;
    blk(m.G, s, ws) = I;
    blk(m.Q, ws, ws) = psd_gm(spec.accel_scale_sigma, spec.scale_tau_s) * I;
  }
  return m;
}

DiscreteErrorModel discretize(const ContinuousErrorModel& model, double dt_s, QdMethod method) {
  const int n = static_cast<int>(model.F.rows());
  // Fixed-capacity temporaries (ErrorMatrix) and products that skip the zeros of F and G (60-90 % of their
  // entries): no heap allocation and a fraction of the dense cost on the per-step path (docs/performance.md).
  const ErrorMatrix Fdt = model.F * dt_s;
  ColumnSparse<kMaxErrorDim> Fs, Gs;
  Fs.assign(model.F);
  Gs.assign(model.G);
  DiscreteErrorModel d;
  ErrorMatrix FF;
  Fs.times(model.F, FF);
  d.Phi = ErrorMatrix::Identity(n, n) + Fdt + (0.5 * dt_s * dt_s) * FF;  // I + FΔt + (FΔt)²/2
  ErrorMatrix GQ, GQGt = ErrorMatrix::Zero(n, n);
  Gs.times(model.Q, GQ);
  Gs.add_times_transposed(GQ, GQGt);  // G Q Gᵀ
  if (method == QdMethod::kSeries) {
    ErrorMatrix FS, FSFt = ErrorMatrix::Zero(n, n);
    Fs.times(GQGt, FS);
    Fs.add_times_transposed(FS, FSFt);
    d.Qd = GQGt * dt_s + 0.5 * (FS + FS.transpose()) * dt_s * dt_s + FSFt * (dt_s * dt_s * dt_s / 3.0);
  } else if (method == QdMethod::kTrapezoidal) {
    d.Qd = 0.5 * (d.Phi * GQGt * d.Phi.transpose() + GQGt) * dt_s;
  } else {
    // Van Loan (1978): A = [[-F, GQG^T], [0, F^T]] Δt, B = exp(A); Φ = B22^T, Qd = Φ B12.
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
    A.topLeftCorner(n, n) = -Fdt;
    A.topRightCorner(n, n) = GQGt * dt_s;
    A.bottomRightCorner(n, n) = Fdt.transpose();
    const Eigen::MatrixXd B = A.exp();
    const Eigen::MatrixXd Phi_exact = B.bottomRightCorner(n, n).transpose();
    d.Qd = Phi_exact * B.topRightCorner(n, n);
  }
  d.Qd = 0.5 * (d.Qd + d.Qd.transpose());
  return d;
}

DiscreteErrorModel interval_error_model(const ErrorStateLayout& layout, const ImuSpec& spec, const NavState& before,
                                        const NavState& after, const ImuIncrement& inc, QdMethod method) {
  const double dt = inc.dt_s;
  const Eigen::Matrix3d R_mid = before.q_e_b.slerp(0.5, after.q_e_b).toRotationMatrix();
  const Eigen::Vector3d p_mid = 0.5 * (before.p_eb_e + after.p_eb_e);
  // Mean specific force of the interval in e (the quantity the attitude error multiplies in eq. 3.2).
  const Eigen::Vector3d f_e_mean = specific_force_increment_e(before, inc) / dt;
  const Eigen::Vector3d f_b = R_mid.transpose() * f_e_mean;
  const Eigen::Vector3d omega_b = inc.alpha_b / dt;
  return discretize(continuous_error_model(layout, spec, R_mid, p_mid, f_b, omega_b), dt, method);
}

Eigen::MatrixXd initial_covariance(const ErrorStateLayout& layout, const ImuSpec& spec, double sigma_pos_m,
                                   double sigma_vel_mps, const Eigen::Vector3d& sigma_att_rad) {
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(layout.dim(), layout.dim());
  auto set = [&](Block b, const Eigen::Vector3d& sigma) {
    P.block(b.offset, b.offset, 3, 3) = sigma.cwiseAbs2().asDiagonal();
  };
  set(kPos, Eigen::Vector3d::Constant(sigma_pos_m));
  set(kVel, Eigen::Vector3d::Constant(sigma_vel_mps));
  set(kAtt, sigma_att_rad);
  const double bg = std::max(spec.gyro_bias_initial, spec.gyro_bias_instability);
  const double ba = std::max(spec.accel_bias_initial, spec.accel_bias_instability);
  set(kBiasGyro, Eigen::Vector3d::Constant(bg));
  set(kBiasAcc, Eigen::Vector3d::Constant(ba));
  if (auto b = layout.find(kScaleGyroBlock)) set(*b, Eigen::Vector3d::Constant(spec.gyro_scale_sigma));
  if (auto b = layout.find(kScaleAccBlock)) set(*b, Eigen::Vector3d::Constant(spec.accel_scale_sigma));
  return P;
}

}  // namespace pednav::ins
