// SPDX-License-Identifier: BSD-2-Clause
// Integer ambiguity resolution (fusion/ambiguity.hpp, docs/carrier.md §3).
#include "fusion/ambiguity.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <map>

#include "gnss/carrier.hpp"
#include "gnss/rtklib/lambda.hpp"

namespace pednav::fusion {
namespace {

// The DD operator of the eligible candidates, grouped by constellation, each against its highest satellite
// (eq. 3.1); `members` gets the candidate positions that appear in it.
Eigen::MatrixXd dd_operator(const std::vector<AmbiguityCandidate>& c, const std::vector<bool>& use, int n_state,
                            std::vector<int>& members) {
  std::map<gnss::System, std::vector<int>> groups;
  for (size_t i = 0; i < c.size(); ++i) {
    if (use[i]) groups[c[i].sat.system].push_back(static_cast<int>(i));
  }
  std::vector<Eigen::MatrixXd> blocks;
  int rows = 0;
  members.clear();
  for (auto& [sys, g] : groups) {
    if (g.size() < 2) continue;
    int ref = 0;
    for (size_t k = 1; k < g.size(); ++k) {
      if (c[g[k]].elevation_rad > c[g[ref]].elevation_rad) ref = static_cast<int>(k);
    }
    std::vector<int> states;
    for (int i : g) states.push_back(c[i].state), members.push_back(i);
    blocks.push_back(gnss::double_difference_operator(states, ref, n_state));
    rows += static_cast<int>(blocks.back().rows());
  }
  Eigen::MatrixXd D(rows, n_state);
  int r = 0;
  for (const auto& b : blocks) D.middleRows(r, b.rows()) = b, r += static_cast<int>(b.rows());
  return D;
}

}  // namespace

const char* solution_status_name(SolutionStatus s) {
  switch (s) {
    case SolutionStatus::kFixed: return "fixed";
    case SolutionStatus::kFloat: return "float";
    case SolutionStatus::kCode: return "code";
    case SolutionStatus::kIns: return "ins";
    case SolutionStatus::kNone: break;
  }
  return "none";
}

int pos_quality(SolutionStatus s) {
  switch (s) {
    case SolutionStatus::kFixed: return 1;
    case SolutionStatus::kFloat: return 2;
    case SolutionStatus::kCode: return 5;
    case SolutionStatus::kIns: return 5;
    case SolutionStatus::kNone: break;
  }
  return 0;
}

AmbiguityFix resolve_ambiguities(const Eigen::VectorXd& x, const Eigen::MatrixXd& P,
                                 const std::vector<AmbiguityCandidate>& candidates, const AmbiguityOptions& o) {
  AmbiguityFix out;
  const int n_state = static_cast<int>(x.size());
  std::vector<bool> use(candidates.size());
  for (size_t i = 0; i < candidates.size(); ++i) {
    const auto& c = candidates[i];
    use[i] = c.integer && c.elevation_rad >= o.ar_elevation_mask_rad && c.lock_epochs >= o.min_lock_epochs;
  }
  // Partial resolution (eq. 3.5): the lowest satellite leaves the set while the set fails, down to min_ambiguities.
  bool first = true;
  std::vector<int> members;
  while (true) {
    const Eigen::MatrixXd D = dd_operator(candidates, use, n_state, members);
    const int m = static_cast<int>(D.rows());
    if (first) out.n_candidates = m;
    if (m < o.min_ambiguities) {
      if (out.why_not.empty()) out.why_not = "too_few_ambiguities";
      return out;
    }
    const Eigen::VectorXd a = D * x;
    const Eigen::MatrixXd Q = D * P * D.transpose();
    auto ils = gnss::integer_least_squares(a, Q);
    if (ils) {
      if (first) out.ratio = ils->ratio(), out.success_rate = ils->success_rate;
      if (ils->ratio() >= o.ratio_threshold && ils->success_rate >= o.min_success_rate) {
        out.fixed = true;
        out.ratio = ils->ratio();
        out.success_rate = ils->success_rate;
        out.D = D;
        out.z = ils->best;
        out.why_not.clear();
        for (int i : members) out.sats.push_back(candidates[i].sat);
        return out;
      }
      if (first) out.why_not = ils->ratio() < o.ratio_threshold ? "ratio" : "success_rate";
    } else if (first) {
      out.why_not = "lambda_failed";
    }
    first = false;
    if (!o.partial) return out;
    // Drop the lowest member that is not the only one of its constellation's reference.
    int lowest = -1;
    for (int i : members) {
      if (lowest < 0 || candidates[i].elevation_rad < candidates[lowest].elevation_rad) lowest = i;
    }
    if (lowest < 0) return out;
    use[lowest] = false;
  }
}

bool condition_on_integers(Eigen::VectorXd& x, Eigen::MatrixXd& P, const Eigen::MatrixXd& D, const Eigen::VectorXd& z,
                           double sigma_cycles) {
  const Eigen::MatrixXd PDt = P * D.transpose();
  Eigen::MatrixXd S = D * PDt;
  S.diagonal().array() += sigma_cycles * sigma_cycles;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 0.0).all()) return false;
  const Eigen::MatrixXd K = ldlt.solve(PDt.transpose()).transpose();
  x += K * (z - D * x);
  const Eigen::MatrixXd IKD = Eigen::MatrixXd::Identity(P.rows(), P.cols()) - K * D;
  P = IKD * P * IKD.transpose() + sigma_cycles * sigma_cycles * K * K.transpose();
  P = 0.5 * (P + P.transpose());
  return true;
}

}  // namespace pednav::fusion
