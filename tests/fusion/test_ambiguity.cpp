// SPDX-License-Identifier: BSD-2-Clause
// Integer ambiguity resolution on a filter state (fusion/ambiguity, docs/carrier.md §3): the double differences are
// fixed to the right integers when the float state is good, refused by the ratio/success-rate tests when it is not,
// partial resolution drops the satellite that spoils the set, GLONASS and young or low ambiguities stay float, and
// the conditioning on the integers is the exact conditional of eq. 3.6.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <random>

#include "fusion/ambiguity.hpp"

namespace pednav::fusion {
namespace {

// A state of 3 position states and 6 SD ambiguities [cycles] whose SD values are integers + a common receiver
// bias (the DD are integers), with position-ambiguity correlation as a float RTK solution has.
struct Problem {
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
  std::vector<AmbiguityCandidate> cands;
  Eigen::VectorXd sd_int;
};

Problem make_problem(double sigma_cycles, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  const int na = 6, n = 3 + na;
  Problem p;
  p.sd_int.resize(na);
  for (int i = 0; i < na; ++i) p.sd_int(i) = std::round(50.0 * n01(rng));
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  p.P = sigma_cycles * sigma_cycles * (A * A.transpose() / n + 0.5 * Eigen::MatrixXd::Identity(n, n));
  // A common bias of the SD ambiguities (receiver phase offset): large variance, it cancels in the DD.
  Eigen::VectorXd common = Eigen::VectorXd::Zero(n);
  common.tail(na).setOnes();
  p.P += 400.0 * common * common.transpose();
  const Eigen::MatrixXd L = p.P.llt().matrixL();
  Eigen::VectorXd noise(n);
  for (int i = 0; i < n; ++i) noise(i) = n01(rng);
  p.x = L * noise;
  p.x.tail(na) += p.sd_int;
  const double el_deg[na] = {70, 55, 40, 30, 25, 20};
  for (int i = 0; i < na; ++i) {
    p.cands.push_back({3 + i, gnss::SatId{gnss::System::kGps, i + 1}, el_deg[i] * kDegToRad, 10, true});
  }
  return p;
}

// The options of these tests: the defaults but 4 double differences at least (the problem has 6 satellites: 5 DD;
// the default of 6 is tested on its own below).
AmbiguityOptions opts() {
  AmbiguityOptions o;
  o.min_ambiguities = 4;
  return o;
}

// The fixed DD integers against the truth: D sd_int.
bool fixed_right(const AmbiguityFix& f, const Problem& p) {
  Eigen::VectorXd full = Eigen::VectorXd::Zero(p.x.size());
  full.tail(p.sd_int.size()) = p.sd_int;
  return (f.D * full - f.z).norm() == 0.0;
}

TEST(Ambiguity, StrongFloatFixesTheRightIntegers) {
  const Problem p = make_problem(0.03, 1);
  const AmbiguityFix f = resolve_ambiguities(p.x, p.P, p.cands, opts());
  ASSERT_TRUE(f.fixed) << f.why_not;
  EXPECT_EQ(f.D.rows(), 5);  // one constellation of 6: 5 DD against the highest
  EXPECT_TRUE(fixed_right(f, p));
  EXPECT_GE(f.ratio, 3.0);
  EXPECT_EQ(f.sats.size(), 6u);
}

TEST(Ambiguity, WeakFloatIsRefused) {
  const Problem p = make_problem(0.6, 2);
  AmbiguityOptions o = opts();
  o.partial = false;
  const AmbiguityFix f = resolve_ambiguities(p.x, p.P, p.cands, o);
  EXPECT_FALSE(f.fixed);
  EXPECT_TRUE(f.why_not == "ratio" || f.why_not == "success_rate") << f.why_not;
  EXPECT_EQ(f.n_candidates, 5);
}

TEST(Ambiguity, PartialResolutionDropsTheSpoilingSatellite) {
  // The lowest satellite's ambiguity is poorly known (σ 2 cycles, uncorrelated): the full set fails, the set without
  // it is fixed.
  Problem p = make_problem(0.03, 3);
  const int low = 3 + 5;
  p.P.row(low).setZero();
  p.P.col(low).setZero();
  p.P(low, low) = 4.0;
  p.x(low) = p.sd_int(5) + 0.5 + p.x(3) - p.sd_int(0);  // half a cycle off in the DD
  AmbiguityOptions full = opts();
  full.partial = false;
  EXPECT_FALSE(resolve_ambiguities(p.x, p.P, p.cands, full).fixed);
  const AmbiguityFix f = resolve_ambiguities(p.x, p.P, p.cands, opts());
  ASSERT_TRUE(f.fixed) << f.why_not;
  EXPECT_EQ(f.D.rows(), 4);
  EXPECT_TRUE(fixed_right(f, p));
  EXPECT_EQ(std::count(f.sats.begin(), f.sats.end(), gnss::SatId{gnss::System::kGps, 6}), 0);
}

TEST(Ambiguity, GlonassYoungAndLowAmbiguitiesStayFloat) {
  Problem p = make_problem(0.03, 4);
  p.cands[1].sat.system = gnss::System::kGlonass;
  p.cands[1].integer = false;
  p.cands[2].lock_epochs = 1;                 // below min_lock_epochs = 3
  p.cands[3].elevation_rad = 10.0 * kDegToRad;  // below the 15° AR mask
  const AmbiguityFix f = resolve_ambiguities(p.x, p.P, p.cands, opts());
  EXPECT_EQ(f.n_candidates, 2);  // 3 GPS candidates left → 2 DD, below min_ambiguities = 4
  EXPECT_FALSE(f.fixed);
  EXPECT_EQ(f.why_not, "too_few_ambiguities");
}

// The default set size (docs/carrier.md §3): fewer than 6 double differences are not fixed, however strong the float.
TEST(Ambiguity, TheDefaultNeedsSixDoubleDifferences) {
  const Problem p = make_problem(0.03, 1);
  EXPECT_EQ(AmbiguityOptions{}.min_ambiguities, 6);
  const AmbiguityFix f = resolve_ambiguities(p.x, p.P, p.cands, AmbiguityOptions{});
  EXPECT_FALSE(f.fixed);
  EXPECT_EQ(f.n_candidates, 5);
  EXPECT_EQ(f.why_not, "too_few_ambiguities");
  EXPECT_TRUE(resolve_ambiguities(p.x, p.P, p.cands, opts()).fixed);
}

TEST(Ambiguity, ConditioningIsTheExactConditional) {
  const Problem p = make_problem(0.03, 5);
  const AmbiguityFix f = resolve_ambiguities(p.x, p.P, p.cands, opts());
  ASSERT_TRUE(f.fixed);
  Eigen::VectorXd x = p.x;
  Eigen::MatrixXd P = p.P;
  ASSERT_TRUE(condition_on_integers(x, P, f.D, f.z, 0.0));
  EXPECT_LT((f.D * x - f.z).norm(), 1e-9);                 // the constraint holds
  EXPECT_LT((f.D * P * f.D.transpose()).norm(), 1e-9);     // and has no variance left
  // The position moves by −P_pa Dᵀ (D P Dᵀ)⁻¹ (D x − z) (eq. 3.6).
  const Eigen::MatrixXd S = f.D * p.P * f.D.transpose();
  const Eigen::VectorXd expect = p.x - p.P * f.D.transpose() * S.ldlt().solve(f.D * p.x - f.z);
  EXPECT_LT((x - expect).norm(), 1e-9);
}

TEST(Ambiguity, HoldWithSigmaLeavesThatVariance) {
  const Problem p = make_problem(0.03, 6);
  const AmbiguityFix f = resolve_ambiguities(p.x, p.P, p.cands, opts());
  ASSERT_TRUE(f.fixed);
  Eigen::VectorXd x = p.x;
  Eigen::MatrixXd P = p.P;
  ASSERT_TRUE(condition_on_integers(x, P, f.D, f.z, 0.01));
  const Eigen::VectorXd var = (f.D * P * f.D.transpose()).diagonal();
  EXPECT_GT(var.minCoeff(), 0.0);
  EXPECT_LT(var.maxCoeff(), 1e-4);  // ≤ σ² = 1e-4 cycles²
}

}  // namespace
}  // namespace pednav::fusion
