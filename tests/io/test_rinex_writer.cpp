// SPDX-License-Identifier: BSD-2-Clause
// RINEX 3.04 writers (io/rinex_writer.*): RTKLIB reads the simulator's obs and nav files back
// (gnss/rtklib/rinex.hpp) with the same values and the same satellite geometry.
#include <gtest/gtest.h>

#include <cmath>

#include "gnss/ephemeris.hpp"
#include "gnss/rtklib/rinex.hpp"
#include "io/rinex_writer.hpp"
#include "sim/simulator.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav {
namespace {

constexpr double kTolObsField = 0.6e-3;   // F14.3 rounding [m, Hz, dB-Hz, cycles]
constexpr double kTolDoppler_hz = 1e-3;   // F14.3 rounding + RTKLIB keeps Doppler as a float (|D| < 5 kHz: 3e-4)
constexpr double kTolSatPos_m = 1e-6;     // nav values are pre-rounded to the RINEX digits: identical states

class RinexReadBack : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto f = test::scenario_from_text(test::kOpenSkyGnssYaml);
    f.scenario.gnss.blunder_rate = 0.005;
    auto s = sim::simulate(f.scenario);
    ASSERT_TRUE(s.has_value());
    sim_ = new sim::Simulation(std::move(*s));
    dir_ = test::temp_dir("rinex_writer");
    ASSERT_TRUE(io::write_rinex_obs(dir_ + "/rover.obs", sim_->gnss.rover, {}).has_value());
    ASSERT_TRUE(io::write_rinex_nav(dir_ + "/nav.rnx", sim_->nav).has_value());
  }
  static void TearDownTestSuite() { delete sim_; }
  static inline sim::Simulation* sim_ = nullptr;
  static inline std::string dir_;
};

TEST_F(RinexReadBack, ObservationsReadBackThroughRtklib) {
  auto obs = gnss::read_rinex_obs(dir_ + "/rover.obs", {});
  ASSERT_TRUE(obs.has_value()) << (obs ? "" : obs.error().message);
  const auto& want = sim_->gnss.rover;
  ASSERT_EQ(obs->epochs.size(), want.epochs.size());
  EXPECT_TRUE(obs->has_approx_position);
  EXPECT_LT((obs->approx_position_e - want.approx_position_e).norm(), 1e-3);
  for (size_t i = 0; i < want.epochs.size(); ++i) {
    const auto &a = obs->epochs[i], &b = want.epochs[i];
    ASSERT_EQ(a.time, b.time);
    ASSERT_EQ(a.sats.size(), b.sats.size());
    for (size_t j = 0; j < b.sats.size(); ++j) {
      EXPECT_EQ(a.sats[j].sat, b.sats[j].sat);
      EXPECT_NEAR(a.sats[j].pseudorange_m, b.sats[j].pseudorange_m, kTolObsField);
      EXPECT_NEAR(a.sats[j].doppler_hz, b.sats[j].doppler_hz, kTolDoppler_hz);
      EXPECT_NEAR(a.sats[j].cn0_dbhz, b.sats[j].cn0_dbhz, 0.13);  // RTKLIB stores S1C in 0.001 dB-Hz? (<= 0.125)
    }
  }
}

TEST_F(RinexReadBack, NavigationReadsBackWithIdenticalGeometry) {
  auto nav = gnss::read_rinex_nav({dir_ + "/nav.rnx"});
  ASSERT_TRUE(nav.has_value()) << (nav ? "" : nav.error().message);
  ASSERT_EQ(nav->kepler.size(), sim_->nav.kepler.size());
  EXPECT_TRUE(nav->has_klobuchar);
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(nav->klobuchar[static_cast<size_t>(i)], sim_->nav.klobuchar[static_cast<size_t>(i)],
                                          1e-4 * std::abs(sim_->nav.klobuchar[static_cast<size_t>(i)]));
  double worst_m = 0, worst_clock_s = 0;
  for (const auto& e : sim_->gnss.rover.epochs) {
    for (const auto& so : e.sats) {
      auto a = gnss::satellite_state(*nav, so.sat, e.time);
      auto b = gnss::satellite_state(sim_->nav, so.sat, e.time);
      ASSERT_TRUE(a && b);
      worst_m = std::max(worst_m, (a->p_es_e - b->p_es_e).norm());
      worst_clock_s = std::max(worst_clock_s, std::abs(a->clock_bias_s - b->clock_bias_s));
    }
  }
  EXPECT_LT(worst_m, kTolSatPos_m);
  EXPECT_LT(worst_clock_s, 1e-15);
}

// Carrier phase (docs/sim.md §8): L1C in cycles and its loss-of-lock indicator read back through RTKLIB; a phase the
// receiver did not track stays absent (blank field) while its code, Doppler and C/N0 are read.
TEST(RinexWriter, CarrierPhaseAndLliReadBackThroughRtklib) {
  auto f = test::scenario_from_text(test::kOpenSkyGnssYaml);
  f.scenario.gnss.carrier_phase = true;
  f.scenario.gnss.carrier_half_cycle_probability = 0.5;
  f.scenario.gnss.attenuation.push_back({40.0, 1e5, "foliage", 5.0, 22.0, 8.0});  // losses of lock
  auto s = sim::simulate(f.scenario);
  ASSERT_TRUE(s.has_value());
  const std::string dir = test::temp_dir("rinex_writer_carrier");
  ASSERT_TRUE(io::write_rinex_obs(dir + "/rover.obs", s->gnss.rover, {}).has_value());
  auto obs = gnss::read_rinex_obs(dir + "/rover.obs", {});
  ASSERT_TRUE(obs.has_value()) << (obs ? "" : obs.error().message);
  const auto& want = s->gnss.rover;
  ASSERT_EQ(obs->epochs.size(), want.epochs.size());
  long phases = 0, blanks = 0, lli_loss = 0, lli_half = 0;
  double worst_cycles = 0.0;
  for (size_t i = 0; i < want.epochs.size(); ++i) {
    const auto &a = obs->epochs[i], &b = want.epochs[i];
    ASSERT_EQ(a.sats.size(), b.sats.size());
    for (size_t j = 0; j < b.sats.size(); ++j) {
      const auto &x = a.sats[j], &y = b.sats[j];
      EXPECT_NEAR(x.pseudorange_m, y.pseudorange_m, kTolObsField);
      ASSERT_EQ(std::isfinite(x.carrier_cycles), std::isfinite(y.carrier_cycles));
      EXPECT_EQ(x.wavelength_m, y.wavelength_m);
      if (!std::isfinite(y.carrier_cycles)) {
        ++blanks;
        continue;
      }
      ++phases;
      worst_cycles = std::max(worst_cycles, std::abs(x.carrier_cycles - y.carrier_cycles));
      EXPECT_EQ(x.lli, y.lli);
      lli_loss += (y.lli & 1) ? 1 : 0;
      lli_half += (y.lli & 2) ? 1 : 0;
    }
  }
  EXPECT_LT(worst_cycles, kTolObsField);
  EXPECT_GT(phases, 1000);
  EXPECT_GT(blanks, 100);
  EXPECT_GT(lli_loss, 10);
  EXPECT_GT(lli_half, 10);
}

TEST(RinexWriter, EmptyInputIsAnError) {
  gnss::ObsData empty;
  empty.marker_name = "X";
  auto r = io::format_rinex_obs(empty, {});
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.error().message.find("no epochs"), std::string::npos);
  auto n = io::format_rinex_nav({});
  ASSERT_FALSE(n.has_value());
  EXPECT_NE(n.error().message.find("no ephemerides"), std::string::npos);
}

}  // namespace
}  // namespace pednav
