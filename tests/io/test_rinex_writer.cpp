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

constexpr double kTolObsField = 0.6e-3;   // F14.3 rounding [m, Hz, dB-Hz]
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
