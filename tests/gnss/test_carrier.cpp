// SPDX-License-Identifier: BSD-2-Clause
// Carrier phase: the SD phase model's Jacobian against central differences, its agreement with the SD code model,
// the phase σ, slip screening (LLI, half cycle, gap, integrated Doppler, a receiver clock step that is not a slip),
// the double-difference operator, and LAMBDA through RTKLIB (docs/carrier.md §1-3).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Cholesky>

#include "gnss/base_phase.hpp"
#include "gnss/carrier.hpp"
#include "gnss/rtklib/lambda.hpp"
#include "tests/support/numdiff.hpp"

namespace pednav::gnss {
namespace {

constexpr double kTolJacobian = 1e-6;
constexpr double kStepPos_m = 1.0;
constexpr double kL1_m = 0.19029367279836487;

SignalAtReceiver phase_signal(const Eigen::Vector3d& p, double phase_range_m) {
  SignalAtReceiver s;
  s.sat.p_es_e = p;
  s.sat.v_es_e = {1200.0, 2500.0, -800.0};
  s.sat.clock_bias_s = 1e-4;
  s.pseudorange_m = phase_range_m;
  return s;
}

const Eigen::Vector3d kRover(3774083.0, -601659.0, 5089316.0), kBase(3774085.6, -601662.6, 5089316.4);
const SignalAtReceiver kRoverSig = phase_signal({1.5e7, -1.2e7, 1.8e7}, 2.2e7);
const SignalAtReceiver kBaseSig = phase_signal({1.5e7 + 3.0, -1.2e7 + 1.0, 1.8e7 - 2.0}, 2.2e7 - 5.0);
const SatId kSat{System::kGps, 5};

TEST(Carrier, SdPhaseJacobian) {
  const MeasurementRow r = sd_carrier_phase(kSat, kRoverSig, kBaseSig, kRover, kBase, 50.0);
  auto f = [](const Eigen::VectorXd& x) {
    Eigen::VectorXd out(1);
    out(0) = -sd_carrier_phase(kSat, kRoverSig, kBaseSig, x.head<3>(), kBase, x(3)).residual;
    return out;
  };
  Eigen::VectorXd x(4);
  x << kRover, 50.0;
  const Eigen::MatrixXd J = test::numerical_jacobian(f, x, kStepPos_m);
  EXPECT_LT((J.block<1, 3>(0, 0) - r.J_p).norm(), kTolJacobian);
  EXPECT_NEAR(J(0, 3), r.J_clock, kTolJacobian);
}

TEST(Carrier, SdPhaseIsTheCodeModelWithPhaseRanges) {
  // Eq. 1.1: an integer number of cycles added to the rover phase moves the residual by exactly λ N.
  SignalAtReceiver rs = kRoverSig;
  const double r0 = sd_carrier_phase(kSat, rs, kBaseSig, kRover, kBase, 50.0).residual;
  rs.pseudorange_m += 17 * kL1_m;
  EXPECT_NEAR(sd_carrier_phase(kSat, rs, kBaseSig, kRover, kBase, 50.0).residual - r0, 17 * kL1_m, 1e-7);
}

TEST(Carrier, TdcpJacobianAgainstCentralDifferences) {
  // Eq. 9.1: the TDCP row w.r.t. the current antenna position, the previous (cloned) one and the clock change.
  const SignalAtReceiver prev = phase_signal({1.5e7 - 3.9e3, -1.2e7 + 1.1e3, 1.8e7 + 2.4e3}, 2.2e7 - 150.0);
  const Eigen::Vector3d p_prev = kRover - Eigen::Vector3d(0.9, -0.6, 0.2);
  const MeasurementRow r = td_carrier_phase(kSat, kRoverSig, prev, kRover, p_prev, 4.0);
  auto f = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd out(1);
    out(0) = -td_carrier_phase(kSat, kRoverSig, prev, x.head<3>(), x.segment<3>(3), x(6)).residual;
    return out;
  };
  Eigen::VectorXd x(7);
  x << kRover, p_prev, 4.0;
  const Eigen::MatrixXd J = test::numerical_jacobian(f, x, kStepPos_m);
  EXPECT_LT((J.block<1, 3>(0, 0) - r.J_p).norm(), kTolJacobian);
  EXPECT_LT((J.block<1, 3>(0, 3) - r.J_v).norm(), kTolJacobian);
  EXPECT_NEAR(J(0, 6), r.J_clock, kTolJacobian);
}

TEST(Carrier, TdcpCancelsTheAmbiguityAndIsTheDifferenceOfTwoEpochs) {
  // An integer number of cycles on both epochs' phases (the same arc) leaves the TDCP residual unchanged; the
  // residual is the current epoch's undifferenced residual minus the previous one's minus the clock change.
  const SignalAtReceiver prev = phase_signal({1.5e7 - 3.9e3, -1.2e7 + 1.1e3, 1.8e7 + 2.4e3}, 2.2e7 - 150.0);
  const Eigen::Vector3d p_prev = kRover - Eigen::Vector3d(0.9, -0.6, 0.2);
  const double r0 = td_carrier_phase(kSat, kRoverSig, prev, kRover, p_prev, 4.0).residual;
  SignalAtReceiver a = kRoverSig, b = prev;
  a.pseudorange_m += 123456 * kL1_m;
  b.pseudorange_m += 123456 * kL1_m;
  EXPECT_NEAR(td_carrier_phase(kSat, a, b, kRover, p_prev, 4.0).residual, r0, 1e-6);
  const double k = ud_pseudorange(kSat, kRoverSig, kRover, 0.0, 0.0, 0.0).residual;
  const double j = ud_pseudorange(kSat, prev, p_prev, 0.0, 0.0, 0.0).residual;
  EXPECT_NEAR(r0, k - j - 4.0, 1e-9);
}

TEST(Carrier, PhaseSigmaFollowsTheWeightModel) {
  WeightModel w;  // cn0_ref 45, elevation weight 1
  EXPECT_NEAR(carrier_sigma_m(w, 0.003, 50.0, kPi / 2), 0.003, 1e-12);
  EXPECT_NEAR(carrier_sigma_m(w, 0.003, 35.0, kPi / 2), 0.003 * std::pow(10.0, 0.5), 1e-12);
  EXPECT_NEAR(carrier_sigma_m(w, 0.003, 50.0, kPi / 6), 0.006, 1e-12);  // 1 / sin 30°
}

TEST(Carrier, IntegerSystems) {
  EXPECT_TRUE(integer_ambiguity_system(System::kGps));
  EXPECT_TRUE(integer_ambiguity_system(System::kGalileo));
  EXPECT_TRUE(integer_ambiguity_system(System::kQzss));
  EXPECT_TRUE(integer_ambiguity_system(System::kBeidou));
  EXPECT_FALSE(integer_ambiguity_system(System::kGlonass));
}

// Three satellites whose phases follow their Dopplers exactly; the test modifies one record per case.
ObsEpoch epoch_at(double t_s, double clock_step_cycles = 0.0) {
  ObsEpoch e;
  e.time = GpsTime::from_ns(static_cast<int64_t>((1000.0 + t_s) * 1e9));
  const double dopp[3] = {-1200.0, 300.0, 2500.0};
  for (int k = 0; k < 3; ++k) {
    SatObs s;
    s.sat = {System::kGps, k + 1};
    s.doppler_hz = dopp[k];
    s.carrier_cycles = 1e7 * (k + 1) - dopp[k] * t_s + clock_step_cycles;
    s.wavelength_m = kL1_m;
    e.sats.push_back(s);
  }
  return e;
}

TEST(PhaseSlipScreen, ContinuousPhasesHaveNoSlip) {
  PhaseSlipScreen s;
  for (int t = 0; t < 5; ++t) {
    for (const auto& r : s.screen(epoch_at(t))) EXPECT_FALSE(r.has_value());
  }
}

TEST(PhaseSlipScreen, FindsEachReason) {
  PhaseSlipScreen s;
  s.screen(epoch_at(0));
  ObsEpoch e = epoch_at(1);
  e.sats[0].carrier_cycles += 5.0;  // an unflagged 5-cycle slip: beyond 3 + 1 cycles
  e.sats[1].lli = kLliSlip;
  auto r = s.screen(e);
  ASSERT_TRUE(r[0].has_value());
  EXPECT_EQ(*r[0], SlipReason::kDoppler);
  ASSERT_TRUE(r[1].has_value());
  EXPECT_EQ(*r[1], SlipReason::kLossOfLock);
  EXPECT_FALSE(r[2].has_value());
  e = epoch_at(2);
  e.sats[0].carrier_cycles += 5.0;  // the slipped phase continues: no second slip
  e.sats[2].lli = kLliHalfCycle;
  r = s.screen(e);
  EXPECT_FALSE(r[0].has_value());
  ASSERT_TRUE(r[2].has_value());
  EXPECT_EQ(*r[2], SlipReason::kHalfCycle);
  e = epoch_at(2 + 11);  // beyond max_gap_s = 10
  r = s.screen(e);
  ASSERT_TRUE(r[1].has_value());
  EXPECT_EQ(*r[1], SlipReason::kGap);
}

TEST(PhaseSlipScreen, SmallSlipBelowThresholdIsNotFlagged) {
  // The Doppler test's limit (3 cycles + 1 cycle/s): a 2-cycle slip is left to the filter's geometry test.
  PhaseSlipScreen s;
  s.screen(epoch_at(0));
  ObsEpoch e = epoch_at(1);
  e.sats[0].carrier_cycles += 2.0;
  EXPECT_FALSE(s.screen(e)[0].has_value());
}

TEST(PhaseSlipScreen, MillionCycleJumpOfOneSatelliteIsASlip) {
  PhaseSlipScreen s;
  s.screen(epoch_at(0));
  ObsEpoch e = epoch_at(1);
  e.sats[1].carrier_cycles += 1e6;
  const auto r = s.screen(e);
  ASSERT_TRUE(r[1].has_value());
  EXPECT_EQ(*r[1], SlipReason::kDoppler);
  EXPECT_FALSE(r[0].has_value());
  EXPECT_FALSE(r[2].has_value());
}

TEST(PhaseSlipScreen, LossOfLockOnEveryEpochIsASlipEveryEpoch) {
  PhaseSlipScreen s;
  int slips = 0;
  for (int t = 0; t < 10; ++t) {
    ObsEpoch e = epoch_at(t);
    for (auto& x : e.sats) x.lli = kLliSlip;
    for (const auto& r : s.screen(e)) slips += r.has_value();
  }
  EXPECT_EQ(slips, 3 * 9);  // every satellite at every epoch after its first
}

TEST(PhaseSlipScreen, SatelliteThatComesAndGoesWithinTheGapKeepsItsArc) {
  // Present on even epochs only (2-s gaps < max_gap_s): the phase still follows the Doppler, no slip.
  PhaseSlipScreen s;
  for (int t = 0; t < 10; ++t) {
    ObsEpoch e = epoch_at(t);
    if (t % 2) e.sats.erase(e.sats.begin());
    for (const auto& r : s.screen(e)) EXPECT_FALSE(r.has_value()) << "epoch " << t;
  }
}

TEST(PhaseSlipScreen, ReceiverClockStepIsNotASlip) {
  // A 1-ms receiver clock step moves every phase by c·1 ms / λ ≈ 1.6e6 cycles and no Doppler: removed by the median.
  PhaseSlipScreen s;
  s.screen(epoch_at(0));
  for (const auto& r : s.screen(epoch_at(1, 299792.458 / kL1_m))) EXPECT_FALSE(r.has_value());
}

TEST(BasePhase, RecordingGapsUpTo60sKeepTheArcAndASlipStartsANewOne) {
  // Base epochs at 0, 30 (a 30-s recording gap, beyond the rover's 10-s limit) and 31 s, with a 5-cycle slip of the
  // first satellite at 31 s.
  std::vector<ObsEpoch> base{epoch_at(0), epoch_at(30), epoch_at(31)};
  base[2].sats[0].carrier_cycles += 5.0;
  const BasePhaseArcs a = screen_base_phase(base, DopplerSlipOptions{});
  ASSERT_EQ(a.arc.size(), 3u);
  EXPECT_EQ(a.arc[1][0], 0);  // across the gap: same arc
  EXPECT_EQ(a.arc[2][0], 1);  // after the slip: a new arc, started by the Doppler test
  EXPECT_EQ(a.arc[2][1], 0);
  ASSERT_TRUE(a.reason(base[2].sats[0].sat, 1).has_value());
  EXPECT_EQ(*a.reason(base[2].sats[0].sat, 1), SlipReason::kDoppler);
  EXPECT_FALSE(a.reason(base[2].sats[1].sat, 0).has_value());
}

TEST(DoubleDifference, OperatorRows) {
  const Eigen::MatrixXd D = double_difference_operator({2, 4, 5}, 1, 7);
  ASSERT_EQ(D.rows(), 2);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(7);
  x(2) = 10, x(4) = 3, x(5) = -1;
  EXPECT_DOUBLE_EQ((D * x)(0), 7.0);
  EXPECT_DOUBLE_EQ((D * x)(1), -4.0);
}

TEST(Lambda, RecoversIntegersOfAStrongProblem) {
  // Float ambiguities = integers + noise drawn from their covariance (correlated, σ ≈ 0.05 cycles): LAMBDA must return
  // the integers, with a large ratio and a success rate near 1.
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  const int n = 6;
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  Eigen::MatrixXd Q = 0.0025 * (A * A.transpose() / n + 0.2 * Eigen::MatrixXd::Identity(n, n));
  const Eigen::MatrixXd L = Q.llt().matrixL();
  Eigen::VectorXd z(n), noise(n);
  for (int i = 0; i < n; ++i) z(i) = std::round(100.0 * n01(rng)), noise(i) = n01(rng);
  const Eigen::VectorXd a = z + L * noise;
  auto s = integer_least_squares(a, Q);
  ASSERT_TRUE(s.has_value()) << s.error().message;
  EXPECT_EQ((s->best - z).norm(), 0.0);
  EXPECT_GT(s->ratio(), 3.0);
  EXPECT_GT(s->success_rate, 0.999);
  EXPECT_LE(s->norm_best, s->norm_second);
}

TEST(Lambda, WeakProblemHasLowRatioAndSuccessRate) {
  // σ = 0.5 cycles on every ambiguity: nothing to fix. The best and second-best differ little.
  const int n = 4;
  const Eigen::MatrixXd Q = 0.25 * Eigen::MatrixXd::Identity(n, n);
  Eigen::VectorXd a(n);
  a << 0.45, 1.52, -2.4, 3.55;
  auto s = integer_least_squares(a, Q);
  ASSERT_TRUE(s.has_value());
  EXPECT_LT(s->ratio(), 1.5);
  // Bootstrapped rate of independent σ = 0.5: (2Φ(1) − 1)^4 = 0.6827^4 = 0.2172.
  EXPECT_NEAR(s->success_rate, std::pow(std::erf(1.0 / std::sqrt(2.0)), 4), 1e-9);
}

TEST(Lambda, RejectsBadInput) {
  Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(2, 2);
  Q(1, 1) = -1.0;
  auto s = integer_least_squares(Eigen::Vector2d(0.1, 0.2), Q);
  ASSERT_FALSE(s.has_value());
  EXPECT_NE(s.error().message.find("not positive definite"), std::string::npos);
  auto t = integer_least_squares(Eigen::Vector2d(std::nan(""), 0.2), Eigen::MatrixXd::Identity(2, 2));
  ASSERT_FALSE(t.has_value());
  EXPECT_NE(t.error().message.find("non-finite"), std::string::npos);
}

}  // namespace
}  // namespace pednav::gnss
