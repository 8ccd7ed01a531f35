// SPDX-License-Identifier: BSD-2-Clause
// Error-state layout, boxplus/boxminus, and the continuous/discrete INS error model (15 core states +
// optional blocks). The definition of the error state is docs/error_state.md (cite it, do not restate it):
//   x_true = x_est ⊞ δx:  p_true = p_est + δp,  v_true = v_est + δv,  R_e_b_true = exp([φ×]) R_e_b_est,
//   b_true = b_est + δb,  s_true = s_est + δs   (φ resolved in e; δx = true ⊟ est).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "ins/imu.hpp"
#include "ins/imu_spec.hpp"
#include "ins/mechanization.hpp"
#include "ins/nav_state.hpp"

namespace pednav::ins {

/// Largest error-state dimension (15 core + scale factors + clocks + ...): the capacity of the matrix types below.
inline constexpr int kMaxErrorDim = 64;
/// Error-state vector and matrix with a compile-time capacity of kMaxErrorDim: sized at run time, stored inline, so
/// the per-epoch path never allocates on the heap (issue 10; docs/performance.md).
using ErrorVector = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxErrorDim, 1>;
using ErrorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxErrorDim, kMaxErrorDim>;
using ErrorRowVector = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxErrorDim>;

/// A contiguous block of the error state.
struct Block {
  int offset;
  int dim;
};
inline constexpr Block kPos{0, 3}, kVel{3, 3}, kAtt{6, 3}, kBiasGyro{9, 3}, kBiasAcc{12, 3};
inline constexpr int kCoreDim = 15;
/// Names of the optional blocks the INS model itself understands (others are owned by their modules).
inline constexpr const char* kScaleGyroBlock = "scale_gyro";
inline constexpr const char* kScaleAccBlock = "scale_acc";
/// The 9 elements of the g-sensitive gyro error matrix G_g, column-major (state 3j + i = G_g(i, j)), random
/// constants (docs/error_state.md §5).
inline constexpr const char* kGSensitivityBlock = "gsens_gyro";  // ≤ 15 characters: no heap allocation per lookup

/// The error-state layout: the 15 core states at fixed offsets, then optional blocks registered at start-up
/// (scale factors, clock, lever arm, ...) appended in registration order.
class ErrorStateLayout {
 public:
  ErrorStateLayout();
  /// Register an optional block of `dim` states at the end; error if the name is taken, dim < 1 or the total would
  /// exceed kMaxErrorDim.
  Expected<Block> add(const std::string& name, int dim);
  /// The block of a registered name (core names: "pos", "vel", "att", "bias_gyro", "bias_acc").
  std::optional<Block> find(const std::string& name) const;
  /// Total dimension.
  int dim() const { return dim_; }
  /// All blocks with names, in state order.
  const std::vector<std::pair<std::string, Block>>& blocks() const { return blocks_; }

 private:
  std::vector<std::pair<std::string, Block>> blocks_;
  int dim_ = 0;
};

/// The INS part of the nominal state: navigation solution plus sensor-error estimates.
struct InsState {
  NavState nav;
  ImuErrors imu;
};

/// x ⊞ δx over the INS blocks (core + scale factors + g-sensitivity if registered); other blocks of δx are ignored.
InsState boxplus(const InsState& x, const Eigen::Ref<const Eigen::VectorXd>& dx, const ErrorStateLayout& layout);
/// δx = a ⊟ b such that a = b ⊞ δx (INS blocks; other blocks zero). φ = log(R_a R_b^T).
Eigen::VectorXd boxminus(const InsState& a, const InsState& b, const ErrorStateLayout& layout);

/// Continuous error model  δẋ = F δx + G w,  E[w w^T] = Q δ(t). w = [n_g, n_a, w_bg, w_ba, (w_sg), (w_sa)].
struct ContinuousErrorModel {
  ErrorMatrix F;  ///< dim x dim [1/s]
  ErrorMatrix G;  ///< dim x nw
  ErrorMatrix Q;  ///< nw x nw power spectral densities (diagonal)
};

/// F, G, Q at the nominal state: attitude R_e_b, position p_eb_e [m] (ECEF), mean specific force f_ib_b
/// [m/s^2] and angular rate omega_ib_b [rad/s] (body, already bias-corrected). docs/error_state.md eq. (3.1)-(3.8).
ContinuousErrorModel continuous_error_model(const ErrorStateLayout& layout, const ImuSpec& spec,
                                            const Eigen::Matrix3d& R_e_b, const Eigen::Vector3d& p_eb_e,
                                            const Eigen::Vector3d& f_ib_b, const Eigen::Vector3d& omega_ib_b);

/// Discretization methods of Qd (docs/error_state.md §4).
enum class QdMethod {
  kSeries,       ///< Qd = S Δt + (F S + S F^T) Δt²/2 + F S F^T Δt³/3, S = G Q G^T (default: Van Loan's integral
                 ///< to third order in Δt; cheap and gets the position-noise term S_vv Δt³/3 right)
  kTrapezoidal,  ///< Qd = 1/2 (Φ S Φ^T + S) Δt (common, but its position block is 3/2 of the exact one)
  kVanLoan,      ///< exact for constant F over Δt (matrix exponential of the 2n x 2n Van Loan matrix)
};

/// Discrete model over Δt: Φ = I + FΔt + 1/2 (FΔt)^2 and Qd.
struct DiscreteErrorModel {
  ErrorMatrix Phi;
  ErrorMatrix Qd;
};

/// Discretize a continuous model over dt_s [s].
DiscreteErrorModel discretize(const ContinuousErrorModel& model, double dt_s, QdMethod method = QdMethod::kSeries);

/// The discrete model of one mechanization interval: F at the interval mid-point (attitude halfway, mean
/// specific force of the increment), so that Φ matches mechanize() to first order. `before` at inc.t0,
/// `after` = mechanize(before, corrected inc); `inc` is the corrected increment.
DiscreteErrorModel interval_error_model(const ErrorStateLayout& layout, const ImuSpec& spec, const NavState& before,
                                        const NavState& after, const ImuIncrement& inc,
                                        QdMethod method = QdMethod::kSeries);

/// The same model (series Q_d) written into `out` (n x n, n = layout.dim(); states outside the INS blocks get an
/// identity transition and no noise): computed from the 3x3 blocks of F and G Q Gᵀ instead of n x n products —
/// the per-step path of the filter (docs/performance.md §1). Equal to discretize(continuous_error_model(…)) up to
/// rounding (tests/ins/test_error_state.cpp).
void interval_error_model(const ErrorStateLayout& layout, const ImuSpec& spec, const NavState& before,
                          const NavState& after, const ImuIncrement& inc, DiscreteErrorModel& out);

/// Initial error covariance (diagonal) from 1-sigma position [m], velocity [m/s], attitude [rad] per axis and
/// the spec's turn-on biases / scale-factor sigmas; other registered blocks are left zero for their owners.
Eigen::MatrixXd initial_covariance(const ErrorStateLayout& layout, const ImuSpec& spec, double sigma_pos_m,
                                   double sigma_vel_mps, const Eigen::Vector3d& sigma_att_rad);

}  // namespace pednav::ins
