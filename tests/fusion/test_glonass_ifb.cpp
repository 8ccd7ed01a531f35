// SPDX-License-Identifier: BSD-2-Clause
// GLONASS inter-frequency phase bias search (fusion/glonass_ifb, docs/carrier.md eqs. 3.9-3.11): the channel from the
// wavelength, the offsets of a β, and the search that finds β from float states whose GLONASS SD ambiguities carry it,
// refuses to take it before the votes agree, and does not search without enough GLONASS.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fusion/glonass_ifb.hpp"
#include "gnss/types.hpp"

namespace pednav::fusion {
namespace {

constexpr double kC = 299792458.0;
double glonass_wavelength(int k) { return kC / (1602.0e6 + k * 0.5625e6); }

TEST(GlonassIfb, ChannelFromTheWavelength) {
  for (int k = -7; k <= 6; ++k) EXPECT_EQ(glonass_channel(glonass_wavelength(k)), k) << k;
  EXPECT_EQ(glonass_channel(kC / 1575.42e6), 0);  // GPS L1: not on the GLONASS grid
  EXPECT_EQ(glonass_channel(kC / (1602.0e6 + 0.3 * 0.5625e6)), 0);
  EXPECT_EQ(glonass_channel(0.0), 0);
  EXPECT_EQ(glonass_channel(std::nan("")), 0);
}

TEST(GlonassIfb, OffsetsAreBetaTimesChannelOverWavelengthOnGlonassOnly) {
  std::vector<AmbiguityCandidate> c;
  c.push_back({1, {gnss::System::kGps, 5}, 0.5, 10, true, kC / 1575.42e6});
  c.push_back({2, {gnss::System::kGlonass, 3}, 0.5, 10, false, glonass_wavelength(-4)});
  c.push_back({4, {gnss::System::kGlonass, 9}, 0.5, 10, false, glonass_wavelength(5)});
  const Eigen::VectorXd d = glonass_ifb_offsets(5, c, -0.05);
  EXPECT_EQ(d(0), 0.0);
  EXPECT_EQ(d(1), 0.0);
  EXPECT_NEAR(d(2), -0.05 * -4 / glonass_wavelength(-4), 1e-12);
  EXPECT_EQ(d(3), 0.0);
  EXPECT_NEAR(d(4), -0.05 * 5 / glonass_wavelength(5), 1e-12);
}

// Float states of 5 GPS and 6 GLONASS SD ambiguities [cycles]: integers, a common receiver term per constellation
// (cancels in the DD), β k / λ on GLONASS, and noise of σ cycles (P says so).
struct Float {
  Eigen::VectorXd x;
  Eigen::MatrixXd P;
  std::vector<AmbiguityCandidate> cands;
};

Float make_float(double beta_m, double sigma_cycles, std::mt19937& rng) {
  std::normal_distribution<double> n01;
  const int channels[6] = {-7, -3, -1, 1, 4, 6};
  const int n = 11;
  Float f;
  f.x.resize(n);
  f.P = sigma_cycles * sigma_cycles * Eigen::MatrixXd::Identity(n, n);
  const double common_g = 0.37, common_r = -0.21;
  for (int i = 0; i < 5; ++i) {
    f.x(i) = std::round(30.0 * n01(rng)) + common_g + sigma_cycles * n01(rng);
    f.cands.push_back({i, {gnss::System::kGps, i + 1}, 0.4 + 0.1 * i, 20, true, kC / 1575.42e6});
  }
  for (int j = 0; j < 6; ++j) {
    const double lam = glonass_wavelength(channels[j]);
    f.x(5 + j) = std::round(30.0 * n01(rng)) + common_r + beta_m * channels[j] / lam + sigma_cycles * n01(rng);
    f.cands.push_back({5 + j, {gnss::System::kGlonass, j + 1}, 0.45 + 0.1 * j, 20, false, lam});
  }
  // The common terms are free (large variance along each constellation's ones vector).
  Eigen::VectorXd g = Eigen::VectorXd::Zero(n), r = Eigen::VectorXd::Zero(n);
  g.head(5).setOnes();
  r.tail(6).setOnes();
  f.P += 100.0 * (g * g.transpose() + r * r.transpose());
  return f;
}

TEST(GlonassIfb, SearchFindsTheBiasRateAfterTheVotesAgree) {
  std::mt19937 rng(7);
  const double beta_true = -0.0535;
  GlonassIfbSearch s;
  AmbiguityOptions ar;
  int taken_at = -1;
  for (int epoch = 0; epoch < 30 && taken_at < 0; ++epoch) {
    const Float f = make_float(beta_true, 0.03, rng);
    if (s.search(f.x, f.P, f.cands, ar)) taken_at = epoch;
  }
  ASSERT_TRUE(s.beta_m().has_value());
  EXPECT_EQ(taken_at, GlonassIfbOptions{}.votes - 1);  // every epoch voted for it: taken at the 10th vote
  EXPECT_NEAR(*s.beta_m(), beta_true, GlonassIfbOptions{}.step_m);
  EXPECT_EQ(s.votes_cast(), GlonassIfbOptions{}.votes);
  // Once taken, β is not searched again.
  const Float f = make_float(beta_true, 0.03, rng);
  EXPECT_FALSE(s.search(f.x, f.P, f.cands, ar));
  EXPECT_EQ(s.searches(), GlonassIfbOptions{}.votes);
}

TEST(GlonassIfb, NoBiasIsFoundNearZero) {
  std::mt19937 rng(11);
  GlonassIfbSearch s;
  AmbiguityOptions ar;
  for (int epoch = 0; epoch < 30 && !s.beta_m(); ++epoch) {
    const Float f = make_float(0.0, 0.03, rng);
    s.search(f.x, f.P, f.cands, ar);
  }
  ASSERT_TRUE(s.beta_m().has_value());
  EXPECT_NEAR(*s.beta_m(), 0.0, GlonassIfbOptions{}.step_m);
}

TEST(GlonassIfb, NoisyFloatsCastNoVotes) {
  std::mt19937 rng(3);
  GlonassIfbSearch s;
  AmbiguityOptions ar;
  for (int epoch = 0; epoch < 20; ++epoch) {
    const Float f = make_float(-0.04, 0.4, rng);  // 0.4 cycles: no β passes the ratio test
    EXPECT_FALSE(s.search(f.x, f.P, f.cands, ar));
  }
  EXPECT_FALSE(s.beta_m().has_value());
  EXPECT_EQ(s.searches(), 20);
  EXPECT_LT(s.votes_cast(), GlonassIfbOptions{}.votes);
}

TEST(GlonassIfb, TooFewGlonassSatellitesAreNotSearched) {
  std::mt19937 rng(5);
  Float f = make_float(-0.05, 0.03, rng);
  f.cands.resize(5 + 2);  // two GLONASS candidates left (fewer than min_glonass = 3)
  GlonassIfbSearch s;
  EXPECT_FALSE(s.search(f.x, f.P, f.cands, AmbiguityOptions{}));
  EXPECT_EQ(s.searches(), 0);
}

}  // namespace
}  // namespace pednav::fusion
