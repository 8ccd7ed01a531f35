#include "fusion/rts.hpp"

#include <Eigen/Cholesky>

namespace pednav::fusion {

using Eigen::MatrixXd;
using Eigen::VectorXd;

RtsStep rts_step(const MatrixXd& P_post, const MatrixXd& Phi, const MatrixXd& P_prior, const MatrixXd& A,
                 const VectorXd& d) {
  // C = P_post Φᵀ P_prior⁻¹ (docs/fusion.md eq. 12.4), from P_prior Cᵀ = Φ P_post. The error state mixes metres,
  // radians and an unconverged clock (variance up to 1e12 m²), so the solve is Jacobi-scaled: with
  // D = diag(P_prior)^(-1/2), (D P_prior D)(D⁻¹ Cᵀ) = D Φ P_post.
  const MatrixXd PhiP = Phi * P_post;
  const VectorXd D = P_prior.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const MatrixXd scaled = D.asDiagonal() * P_prior * D.asDiagonal();
  const Eigen::LDLT<MatrixXd> ldlt(scaled);
  const MatrixXd Ct = D.asDiagonal() * ldlt.solve(D.asDiagonal() * PhiP);
  const MatrixXd C = Ct.transpose();
  RtsStep s;
  s.G = C * A;                                   // eq. 12.7
  s.g = C * d;                                   // eq. 12.7
  s.Sigma = P_post - C * PhiP;                   // eq. 12.6: P_post − C P_prior Cᵀ = P_post − C Φ P_post
  s.Sigma = 0.5 * (s.Sigma + s.Sigma.transpose());
  return s;
}

void RtsAccumulator::reset(int n) {
  seg_.M = MatrixXd::Identity(n, n);
  seg_.m = VectorXd::Zero(n);
  seg_.S = MatrixXd::Zero(n, n);
  steps_ = 0;
}

void RtsAccumulator::append(const RtsStep& step) {
  // ŝ_a = M ŝ_j + m with ŝ_j = G ŝ_{j+1} + g  ⇒  M ← M G, m ← m + M g; P likewise: S ← S + M Σ Mᵀ (eq. 12.9).
  seg_.m += seg_.M * step.g;
  seg_.S += seg_.M * step.Sigma * seg_.M.transpose();
  seg_.M = seg_.M * step.G;
  ++steps_;
}

RtsSegment RtsAccumulator::take() {
  RtsSegment out = std::move(seg_);
  out.S = 0.5 * (out.S + out.S.transpose());
  reset(static_cast<int>(out.M.rows()));
  return out;
}

std::vector<RtsSmoothed> rts_backward(const std::vector<RtsSegment>& segments, const RtsSegment& tail,
                                      const MatrixXd& P_last) {
  std::vector<RtsSmoothed> out(segments.size() + 1);
  // At the last step the smoothed error is the filtered one, zero after the closed-loop reset (eq. 12.10).
  RtsSmoothed cur;
  cur.dx = tail.m;
  cur.P = tail.S + tail.M * P_last * tail.M.transpose();
  out.back() = cur;
  for (size_t i = segments.size(); i-- > 0;) {
    const RtsSegment& s = segments[i];
    cur.dx = s.M * cur.dx + s.m;
    cur.P = s.S + s.M * cur.P * s.M.transpose();
    cur.P = 0.5 * (cur.P + cur.P.transpose());
    out[i] = cur;
  }
  return out;
}

}  // namespace pednav::fusion
