// SPDX-License-Identifier: BSD-2-Clause
// Error-state model (docs/error_state.md). State order: δp_e [0,3), δv_e [3,6), φ_e [6,9), δb_g [9,12),
// δb_a [12,15), then registered optional blocks. Noise order: n_g, n_a, w_bg, w_ba, (w_sg), (w_sa).
#include "ins/error_state.hpp"

#include <array>
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
  if (auto b = layout.find(kGSensitivityBlock)) y.imu.G_g += dx.segment<9>(b->offset).reshaped(3, 3);
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
  if (auto s = layout.find(kGSensitivityBlock)) dx.segment<9>(s->offset) = (a.imu.G_g - b.imu.G_g).reshaped();
  return dx;
}

// docs/error_state.md eq. (3.1)-(3.8):
//   δṗ = δv
//   δv̇ = Γ δp - 2[ω_ie×] δv - [f_e×] φ - R δb_a - R diag(f_b) δs_a - R n_a
//   φ̇  = -[ω_ie×] φ - R δb_g - R diag(ω_b) δs_g - R δG_g f_b - R n_g   (δG_g f_b = Σ_j f_b,j δG_g[:, j], docs/error_state.md §5)
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
  if (const auto gs = layout.find(kGSensitivityBlock)) {  // random constants: no dynamics, no noise
    for (int j = 0; j < 3; ++j) m.F.block(kAtt.offset, gs->offset + 3 * j, 3, 3) = -R_e_b * f_ib_b(j);
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

namespace {

// The INS error model of eq. (3.1)-(3.8) as a matrix of 3x3 blocks (at most 10 x 10: pos, vel, att, gyro bias,
// accel bias, gyro scale, accel scale, the three columns of G_g) with a flag per nonzero block: Φ and Q_d of the
// series method are products of a few 3x3 blocks (docs/error_state.md §4, docs/performance.md §1), not of n x n
// matrices.
constexpr int kMaxInsBlocks = 10;
struct Blocks3 {
  std::array<int, kMaxInsBlocks> offset{};
  int count = 0;
  std::array<std::array<Eigen::Matrix3d, kMaxInsBlocks>, kMaxInsBlocks> m;
  std::array<std::array<bool, kMaxInsBlocks>, kMaxInsBlocks> nz{};
  void set(int i, int j, const Eigen::Matrix3d& v) {
    m[i][j] = v;
    nz[i][j] = true;
  }
};

// Φ = I + FΔt + (FΔt)²/2 and Q_d = SΔt + (FS + SFᵀ)Δt²/2 + FSFᵀΔt³/3 (S = G Q Gᵀ, block-diagonal) from the
// blocks of F and S; written into the n x n matrices of d (other states: identity transition, no noise). Every
// noise of eq. (3.1)-(3.8) is isotropic, so each diagonal block of S is a multiple of I (S_vv = R σ² I Rᵀ = σ² I):
// s[k] holds it.
void discretize_blocks(const Blocks3& F, const std::array<double, kMaxInsBlocks>& s, int n, double dt,
                       DiscreteErrorModel& d) {
  const int nb = F.count;
  const double h2 = 0.5 * dt * dt, h3 = dt * dt * dt / 3.0;
  d.Phi.setIdentity(n, n);
  d.Qd.setZero(n, n);
  for (int i = 0; i < nb; ++i) {
    const int ri = F.offset[i];
    for (int j = 0; j < nb; ++j) {
      // Φ_ij = F_ij Δt + Σ_k F_ik F_kj Δt²/2 (+ I on the diagonal, already set).
      bool any = F.nz[i][j];
      Eigen::Matrix3d phi = any ? Eigen::Matrix3d(F.m[i][j] * dt) : Eigen::Matrix3d::Zero();
      for (int k = 0; k < nb; ++k) {
        if (F.nz[i][k] && F.nz[k][j]) {
          phi.noalias() += (F.m[i][k] * F.m[k][j]) * h2;
          any = true;
        }
      }
      if (any) d.Phi.block<3, 3>(ri, F.offset[j]) += phi;
      if (j < i) continue;  // Q_d is symmetric: the upper blocks, mirrored
      // Q_d,ij = S_ij Δt + (F_ij S_jj + S_ii F_jiᵀ) Δt²/2 + Σ_k F_ik S_kk F_jkᵀ Δt³/3.
      Eigen::Matrix3d q = Eigen::Matrix3d::Zero();
      any = false;
      if (i == j && s[i] != 0.0) {
        q.diagonal().setConstant(s[i] * dt);
        any = true;
      }
      if (F.nz[i][j] && s[j] != 0.0) {
        q += (s[j] * h2) * F.m[i][j];
        any = true;
      }
      if (F.nz[j][i] && s[i] != 0.0) {
        q += (s[i] * h2) * F.m[j][i].transpose();
        any = true;
      }
      for (int k = 0; k < nb; ++k) {
        if (F.nz[i][k] && F.nz[j][k] && s[k] != 0.0) {
          q.noalias() += (s[k] * h3) * (F.m[i][k] * F.m[j][k].transpose());
          any = true;
        }
      }
      if (!any) continue;
      if (i == j) {
        d.Qd.block<3, 3>(ri, ri) = 0.5 * (q + q.transpose());
      } else {
        d.Qd.block<3, 3>(ri, F.offset[j]) = q;
        d.Qd.block<3, 3>(F.offset[j], ri) = q.transpose();
      }
    }
  }
}

// The nominal quantities F is evaluated at for one interval: attitude halfway, mid-point position, mean specific
// force of the increment in e (the quantity the attitude error multiplies in eq. 3.2) and in b, mean rate.
struct IntervalMidpoint {
  Eigen::Matrix3d R;
  Eigen::Vector3d p_mid, f_e, f_b, omega_b;
};
IntervalMidpoint interval_midpoint(const NavState& before, const NavState& after, const ImuIncrement& inc) {
  IntervalMidpoint m;
  m.R = before.q_e_b.slerp(0.5, after.q_e_b).toRotationMatrix();
  m.p_mid = 0.5 * (before.p_eb_e + after.p_eb_e);
  m.f_e = specific_force_increment_e(before, inc) / inc.dt_s;
  m.f_b = m.R.transpose() * m.f_e;
  m.omega_b = inc.alpha_b / inc.dt_s;
  return m;
}

}  // namespace

void interval_error_model(const ErrorStateLayout& layout, const ImuSpec& spec, const NavState& before,
                          const NavState& after, const ImuIncrement& inc, DiscreteErrorModel& out) {
  const double dt = inc.dt_s;
  const auto [R, p_mid, f_e, f_b, omega_b] = interval_midpoint(before, after, inc);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d W = skew(kOmegaIE_e);
  auto psd_gm = [](double sigma, double tau) { return tau > 0.0 ? 2.0 * sigma * sigma / tau : 0.0; };

  // Blocks of F (eq. 3.1-3.8; the same entries as continuous_error_model) and of S = G Q Gᵀ (block-diagonal:
  // every noise drives one block).
  enum { P, V, A, BG, BA };
  Blocks3 F;
  std::array<double, kMaxInsBlocks> S{};  // S_kk = S[k] I
  F.count = 5;
  F.offset = {kPos.offset, kVel.offset, kAtt.offset, kBiasGyro.offset, kBiasAcc.offset, 0, 0, 0, 0, 0};
  F.set(P, V, I);
  F.set(V, P, gravity_gradient_ecef(p_mid));
  F.set(V, V, -2.0 * W);
  F.set(V, A, -skew(f_e));
  F.set(V, BA, -R);
  F.set(A, A, -W);
  F.set(A, BG, -R);
  if (spec.gyro_bias_tau_s > 0.0) F.set(BG, BG, -I / spec.gyro_bias_tau_s);
  if (spec.accel_bias_tau_s > 0.0) F.set(BA, BA, -I / spec.accel_bias_tau_s);
  S[P] = 0.0;
  S[V] = spec.accel_vrw * spec.accel_vrw;  // R (σ² I) Rᵀ
  S[A] = spec.gyro_arw * spec.gyro_arw;
  S[BG] = psd_gm(spec.gyro_bias_instability, spec.gyro_bias_tau_s) + spec.gyro_bias_rw * spec.gyro_bias_rw;
  S[BA] = psd_gm(spec.accel_bias_instability, spec.accel_bias_tau_s) + spec.accel_bias_rw * spec.accel_bias_rw;
  if (const auto sg = layout.find(kScaleGyroBlock)) {
    const int s = F.count++;
    F.offset[s] = sg->offset;
    F.set(A, s, -R * omega_b.asDiagonal());
    if (spec.scale_tau_s > 0.0) F.set(s, s, -I / spec.scale_tau_s);
    S[s] = psd_gm(spec.gyro_scale_sigma, spec.scale_tau_s);
  }
  if (const auto sa = layout.find(kScaleAccBlock)) {
    const int s = F.count++;
    F.offset[s] = sa->offset;
    F.set(V, s, -R * f_b.asDiagonal());
    if (spec.scale_tau_s > 0.0) F.set(s, s, -I / spec.scale_tau_s);
    S[s] = psd_gm(spec.accel_scale_sigma, spec.scale_tau_s);
  }
  if (const auto gs = layout.find(kGSensitivityBlock)) {  // column j of G_g: φ̇ ∋ −R f_b,j δG_g[:, j] (docs/error_state.md eq. 5.3)
    for (int j = 0; j < 3; ++j) {
      const int s = F.count++;
      F.offset[s] = gs->offset + 3 * j;
      F.set(A, s, -R * f_b(j));
      S[s] = 0.0;
    }
  }
  discretize_blocks(F, S, layout.dim(), dt, out);
}

DiscreteErrorModel interval_error_model(const ErrorStateLayout& layout, const ImuSpec& spec, const NavState& before,
                                        const NavState& after, const ImuIncrement& inc, QdMethod method) {
  if (method == QdMethod::kSeries) {
    DiscreteErrorModel d;
    interval_error_model(layout, spec, before, after, inc, d);
    return d;
  }
  const IntervalMidpoint m = interval_midpoint(before, after, inc);
  return discretize(continuous_error_model(layout, spec, m.R, m.p_mid, m.f_b, m.omega_b), inc.dt_s, method);
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
  if (auto b = layout.find(kGSensitivityBlock)) {
    const double v = spec.gyro_g_sensitivity * spec.gyro_g_sensitivity;
    P.block(b->offset, b->offset, 9, 9) = v * Eigen::MatrixXd::Identity(9, 9);
  }
  return P;
}

}  // namespace pednav::ins
