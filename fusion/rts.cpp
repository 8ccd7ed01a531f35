// SPDX-License-Identifier: BSD-2-Clause
#include "fusion/rts.hpp"

#include <Eigen/Cholesky>

namespace pednav::fusion {

RtsStep rts_step(const ErrorMatrix& P_post, const ErrorMatrix& Phi, const ErrorMatrix& P_prior, const ErrorMatrix& A,
                 const ErrorVector& d) {
  RtsStep s;
  rts_step(P_post, Phi, P_prior, A, d, s);
  return s;
}

void rts_step(const ErrorMatrix& P_post, const ErrorMatrix& Phi, const ErrorMatrix& P_prior, const ErrorMatrix& A,
              const ErrorVector& d, RtsStep& s) {
  ErrorMatrix PhiP;
  PhiP.noalias() = Phi * P_post;
  rts_step(P_post, Phi, P_prior, A, d, PhiP, s);
}

void rts_step(const ErrorMatrix& P_post, const ErrorMatrix& /*Phi*/, const ErrorMatrix& P_prior, const ErrorMatrix& A,
              const ErrorVector& d, const ErrorMatrix& PhiP, RtsStep& s) {
  // C = P_post Φᵀ P_prior⁻¹ (docs/fusion.md eq. 12.4), from P_prior Cᵀ = Φ P_post. The error state mixes metres,
  // radians and an unconverged clock (variance up to 1e12 m²), so the solve is Jacobi-scaled: with
  // D = diag(P_prior)^(-1/2), (D P_prior D)(D⁻¹ Cᵀ) = D Φ P_post.
  const ErrorVector D = P_prior.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const ErrorMatrix scaled = D.asDiagonal() * P_prior * D.asDiagonal();
  const Eigen::LDLT<ErrorMatrix> ldlt(scaled);
  const ErrorMatrix Ct = D.asDiagonal() * ldlt.solve(D.asDiagonal() * PhiP);
  const ErrorMatrix C = Ct.transpose();
  // G = C A (eq. 12.7). A is the identity but for the columns the form-D re-expression touched (eq. 12.3): those
  // columns are multiplied, the others copied (C e_j = column j of C exactly).
  s.G = C;
  const int n = static_cast<int>(A.cols());
  for (int j = 0; j < n; ++j) {
    bool unit = true;
    for (int i = 0; i < n && unit; ++i) unit = A(i, j) == (i == j ? 1.0 : 0.0);
    if (!unit) s.G.col(j).noalias() = C * A.col(j);
  }
  s.g.noalias() = C * d;                         // eq. 12.7
  s.Sigma = P_post;                              // eq. 12.6: P_post − C P_prior Cᵀ = P_post − C Φ P_post
  s.Sigma.noalias() -= C * PhiP;
  s.Sigma = 0.5 * (s.Sigma + s.Sigma.transpose()).eval();
}

void RtsAccumulator::reset(int n) {
  seg_.M.setIdentity(n, n);
  seg_.m.setZero(n);
  seg_.S.setZero(n, n);
  steps_ = 0;
}

void RtsAccumulator::append(const RtsStep& step) {
  // ŝ_a = M ŝ_j + m with ŝ_j = G ŝ_{j+1} + g  ⇒  M ← M G, m ← m + M g; P likewise: S ← S + M Σ Mᵀ (eq. 12.9).
  seg_.m.noalias() += seg_.M * step.g;
  tmp_.noalias() = seg_.M * step.Sigma;
  seg_.S.noalias() += tmp_ * seg_.M.transpose();
  tmp_.noalias() = seg_.M * step.G;
  seg_.M = tmp_;
  ++steps_;
}

RtsSegment RtsAccumulator::take() {
  RtsSegment out = seg_;
  out.S = 0.5 * (out.S + out.S.transpose()).eval();
  reset(static_cast<int>(out.M.rows()));
  return out;
}

void RtsInterval::restart(const ErrorMatrix& P_a) {
  // At a the error is δx_a itself: Cov(δx_a, δx_a) = Var(δx_a | Y_a) = P_a|a, E[δx_a | Y_a] = 0 (eq. 12.14).
  Gamma_ = P_a;
  V_ = P_a;
  mu_.setZero(P_a.rows());
  steps_ = 0;
}

void RtsInterval::restart(const ErrorMatrix& P_a, const ErrorVector& eta_a) {
  restart(P_a);
  mu_ = eta_a;  // eq. 12.21: E[δx_a | Y_a] = η_a
}

void RtsInterval::predict(const RowTransition<ins::kMaxErrorDim>& Phi) {
  // Γ ← Γ Φᵀ in place (eq. 12.15): the columns of Φ's dense rows as sums of whole columns of Γ, the others scaled
  // by Φ_rr (or left alone when it is 1).
  Phi.times_transposed_in_place(Gamma_, tmp_);
  ++steps_;
}

void RtsInterval::predict(const ErrorMatrix& Phi) {
  tmp_.noalias() = Gamma_ * Phi.transpose();
  Gamma_ = tmp_;
  ++steps_;
}

void RtsInterval::reexpress(int dst, int src, const Eigen::Matrix3d& B) {
  // Γ Jᵀ = Γ + Γ E_src Bᵀ E_dstᵀ: only the dst columns change (the blocks are disjoint, no aliasing; eq. 12.18).
  Gamma_.middleCols<3>(dst).noalias() += Gamma_.middleCols<3>(src) * B.transpose();
}

void RtsInterval::shift_mean_regressed(const int* states, const double* delta, int n, const ErrorMatrix& P) {
  constexpr int kMaxStates = 6;  // gyro + accelerometer scale factors
  using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxStates, kMaxStates>;
  using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxStates, 1>;
  if (n <= 0) return;
  Small P_SS(std::min(n, kMaxStates), std::min(n, kMaxStates));
  SmallVec d(P_SS.rows());
  for (int a = 0; a < P_SS.rows(); ++a) {
    d(a) = delta[a];
    for (int b = 0; b < P_SS.rows(); ++b) P_SS(a, b) = P(states[a], states[b]);
  }
  const Eigen::LLT<Small> llt(P_SS);
  if (n > kMaxStates || llt.info() != Eigen::Success) {
    for (int a = 0; a < n; ++a) shift_mean(states[a], delta[a]);
    return;
  }
  const SmallVec y = llt.solve(d);
  for (int a = 0; a < n; ++a) mu_.noalias() += Gamma_.col(states[a]) * y(a);
}

// A fresh variable is uncorrelated with δx_a (eq. 12.19).
void RtsInterval::restart_state(int i) {
  Gamma_.col(i).setZero();
}

void RtsInterval::close(const ErrorMatrix& P_b, RtsSegment& out) const { close(P_b, nullptr, out); }

void RtsInterval::close(const ErrorMatrix& P_b, const ErrorVector& eta_b, RtsSegment& out) const {
  close(P_b, &eta_b, out);
}

void RtsInterval::close(const ErrorMatrix& P_b, const ErrorVector* eta_b, RtsSegment& out) const {
  const int n = static_cast<int>(Gamma_.rows());
  if (steps_ == 0) {  // b = a: the identity map (what the per-step composition gives for no steps)
    out.M.setIdentity(n, n);
    out.m.setZero(n);
    out.S.setZero(n, n);
    return;
  }
  // M = Γ P_b|b⁻¹ from P_b|b Mᵀ = Γᵀ (eq. 12.20), Jacobi-scaled as in rts_step (metres, radians and clock variances
  // up to 1e12 m² in one matrix): D = diag(P_b|b)^(-1/2), (D P D)(D⁻¹ Mᵀ) = D Γᵀ.
  const ErrorVector D = P_b.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const ErrorMatrix scaled = D.asDiagonal() * P_b * D.asDiagonal();
  const Eigen::LDLT<ErrorMatrix> ldlt(scaled);
  const ErrorMatrix Mt = D.asDiagonal() * ldlt.solve(D.asDiagonal() * Gamma_.transpose());
  out.M = Mt.transpose();
  // E[δx_a | δx_b, Y_b] = μ + M (δx_b − η_b) (eq. 12.24; η_b = 0 for a Kalman gain, eq. 12.20).
  out.m = mu_;
  if (eta_b) out.m.noalias() -= out.M * *eta_b;
  out.S = V_;  // S = Var(δx_a | δx_b, Y_b) = V − M Γᵀ (eq. 12.20)
  out.S.noalias() -= out.M * Gamma_.transpose();
  out.S = 0.5 * (out.S + out.S.transpose()).eval();
}

void RtsStore::push(const RtsSegment& s) {
  const int n = n_;
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < n; ++r) data_.push_back(s.M(r, c));
  }
  for (int r = 0; r < n; ++r) data_.push_back(s.m(r));
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r <= c; ++r) data_.push_back(s.S(r, c));
  }
}

void RtsStore::get(size_t i, RtsSegment& out) const {
  const int n = n_;
  const double* p = data_.data() + i * record_doubles();
  out.M.resize(n, n);
  out.m.resize(n);
  out.S.resize(n, n);
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r < n; ++r) out.M(r, c) = *p++;
  }
  for (int r = 0; r < n; ++r) out.m(r) = *p++;
  for (int c = 0; c < n; ++c) {
    for (int r = 0; r <= c; ++r) out.S(r, c) = out.S(c, r) = *p++;
  }
}

void rts_backward(const RtsStore& store, const RtsSegment& tail, const ErrorMatrix& P_last,
                  const std::function<void(size_t, const ErrorVector&, const ErrorMatrix&)>& visit) {
  // At the last step the smoothed error is the filtered one, zero after the closed-loop reset (eq. 12.10).
  rts_backward(store, tail, P_last, ErrorVector::Zero(P_last.rows()), visit);
}

void rts_backward(const RtsStore& store, const RtsSegment& tail, const ErrorMatrix& P_last,
                  const ErrorVector& eta_last,
                  const std::function<void(size_t, const ErrorVector&, const ErrorMatrix&)>& visit) {
  // At the last step the smoothed error is the filtered conditional mean η_N (eq. 12.25; 0 for a Kalman gain).
  ErrorVector dx = tail.m;
  dx.noalias() += tail.M * eta_last;
  ErrorMatrix P = tail.S + tail.M * P_last * tail.M.transpose();
  visit(store.size(), dx, P);
  RtsSegment s;
  ErrorMatrix tmp;
  for (size_t i = store.size(); i-- > 0;) {
    store.get(i, s);
    dx = (s.M * dx + s.m).eval();
    tmp.noalias() = s.M * P;
    P = s.S;
    P.noalias() += tmp * s.M.transpose();
    P = 0.5 * (P + P.transpose()).eval();
    visit(i, dx, P);
  }
}

std::vector<RtsSmoothed> rts_backward(const std::vector<RtsSegment>& segments, const RtsSegment& tail,
                                      const ErrorMatrix& P_last) {
  return rts_backward(segments, tail, P_last, ErrorVector::Zero(P_last.rows()));
}

std::vector<RtsSmoothed> rts_backward(const std::vector<RtsSegment>& segments, const RtsSegment& tail,
                                      const ErrorMatrix& P_last, const ErrorVector& eta_last) {
  RtsStore store(static_cast<int>(tail.M.rows()));
  store.reserve(segments.size());
  for (const RtsSegment& s : segments) store.push(s);
  std::vector<RtsSmoothed> out(segments.size() + 1);
  rts_backward(store, tail, P_last, eta_last, [&](size_t i, const ErrorVector& dx, const ErrorMatrix& P) {
    out[i].dx = dx;
    out[i].P = P;
  });
  return out;
}

}  // namespace pednav::fusion
