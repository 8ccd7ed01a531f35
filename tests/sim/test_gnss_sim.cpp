// SPDX-License-Identifier: BSD-2-Clause
// GNSS observation simulation (sim/gnss_sim.*, sim/constellation.*): with the true positions and clocks the
// single-difference residuals have the configured standard deviations; blunders appear at the configured
// rate and are recorded; the nominal constellation is a proper 24+ satellite GPS constellation.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "core/geodesy.hpp"
#include "gnss/ephemeris.hpp"
#include "gnss/measurement.hpp"
#include "sim/constellation.hpp"
#include "sim/gnss_sim.hpp"
#include "sim/simulator.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav {
namespace {

constexpr double kTolSigmaRatio = 0.10;   // issue 4: configured SD within 10 %
constexpr double kC = kSpeedOfLight_mps;
constexpr double kLambdaL1_m = kC / 1575.42e6;

struct SdResidual {
  GpsTime t;
  gnss::SatId sat;
  double code_m, rate_mps;          // measured - true
  double sigma_code_m, sigma_rate_mps;  // configured
};

// SD residuals of every common rover/base observation with the simulator's truth.
std::vector<SdResidual> sd_residuals(const sim::Simulation& s) {
  const auto ant = sim::antenna_function(s.scenario, s.frame, s.plan);
  const sim::GnssOptions& o = s.scenario.gnss;
  std::map<int64_t, const gnss::ObsEpoch*> base;
  for (const auto& e : s.gnss.base.epochs) base[e.time.ns()] = &e;
  std::map<int64_t, const sim::ClockTruth*> clocks;
  for (const auto& c : s.gnss.clocks) clocks[c.t.ns()] = &c;
  std::vector<SdResidual> out;
  for (const auto& er : s.gnss.rover.epochs) {
    const auto b = base.find(er.time.ns());
    if (b == base.end()) continue;
    const sim::ClockTruth& clk = *clocks.at(er.time.ns());
    const sim::AntennaTruth ar = ant(er.time.plus_s(-clk.rover_bias_s));
    for (const auto& r : er.sats) {
      for (const auto& q : b->second->sats) {
        if (q.sat != r.sat) continue;
        auto sr = gnss::satellite_state_at_reception(s.nav, r.sat, er.time, r.pseudorange_m);
        auto sb = gnss::satellite_state_at_reception(s.nav, q.sat, er.time, q.pseudorange_m);
        const auto lr = gnss::line_of_sight(*sr, ar.p_e, ar.v_e);
        const auto lb = gnss::line_of_sight(*sb, s.gnss.p_base_e, Eigen::Vector3d::Zero());
        const double code = (r.pseudorange_m - q.pseudorange_m) - (lr.range_m - lb.range_m) -
                            kC * (clk.rover_bias_s - clk.base_bias_s) + kC * (sr->clock_bias_s - sb->clock_bias_s);
        const double rate = -kLambdaL1_m * (r.doppler_hz - q.doppler_hz) - (lr.range_rate_mps - lb.range_rate_mps) -
                            kC * (clk.rover_drift - clk.base_drift) + kC * (sr->clock_drift_sps - sb->clock_drift_sps);
        const double el = gnss::elevation_azimuth(ar.p_e, sr->p_es_e).elevation;
        const double th = sim::thermal_code_sigma_m(o, r.cn0_dbhz), mp = sim::multipath_sigma_m(o, r.cn0_dbhz);
        const double atm = o.atmosphere_sd_ppm * 1e-6 * (ar.p_e - s.gnss.p_base_e).norm() / std::sin(el);
        const double dop = sim::doppler_sigma_mps(o, r.cn0_dbhz);
        out.push_back({er.time, r.sat, code, rate, std::sqrt(2 * th * th + 2 * mp * mp + atm * atm), std::sqrt(2.0) * dop});
      }
    }
  }
  return out;
}

sim::Simulation run(const char* yaml, double blunder_rate = 0.0) {
  auto f = test::scenario_from_text(yaml);
  f.scenario.gnss.blunder_rate = blunder_rate;
  auto s = sim::simulate(f.scenario);
  EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
  return std::move(*s);
}

TEST(GnssSim, SdResidualsWithTruthHaveTheConfiguredSigmas) {
  const sim::Simulation s = run(test::kOpenSkyGnssYaml);
  const auto res = sd_residuals(s);
  ASSERT_GT(res.size(), 5000u);
  double sc = 0, sr = 0, atm_share = 0;
  for (const auto& r : res) {
    sc += std::pow(r.code_m / r.sigma_code_m, 2);
    sr += std::pow(r.rate_mps / r.sigma_rate_mps, 2);
    atm_share += r.sigma_code_m;
  }
  const double ratio_code = std::sqrt(sc / res.size()), ratio_rate = std::sqrt(sr / res.size());
  std::printf("SD code residual std / configured %.3f, range rate %.3f (%zu residuals, mean sigma %.2f m)\n", ratio_code,
              ratio_rate, res.size(), atm_share / res.size());
  EXPECT_NEAR(ratio_code, 1.0, kTolSigmaRatio);  // issue 4
  EXPECT_NEAR(ratio_rate, 1.0, kTolSigmaRatio);
  // Measured 2026-12-05 (fixed seed, deterministic): 0.998 and 1.012 over 7467 residuals, mean σ 1.98 m. A sample σ
  // ratio over N residuals spreads by ~1/√(2N) = 0.8 % for independent ones; the multipath (τ 20 s) correlates them,
  // so a change of the random sequence (another draw order) may move it by a few %: ±3 % of 1 beside the issue's
  // ±10 %. The residual count and the mean σ are functions of the scenario's geometry: ±1 %.
  EXPECT_NEAR(ratio_code, 1.0, 0.03);
  EXPECT_NEAR(ratio_rate, 1.0, 0.03);
  EXPECT_NEAR(static_cast<double>(res.size()), 7467.0, 0.01 * 7467.0);
  EXPECT_NEAR(atm_share / res.size(), 1.98, 0.01 * 1.98);
}

TEST(GnssSim, ResidualAtmosphereGrowsWithBaseline) {
  auto f = test::scenario_from_text(test::kOpenSkyGnssYaml);
  auto near = f.scenario, far = f.scenario;
  near.gnss.base_offset_enu_m = Eigen::Vector3d(30, 40, 0);
  far.gnss.base_offset_enu_m = Eigen::Vector3d(3000, 4000, 0);
  auto sn = sim::simulate(near), sf = sim::simulate(far);
  ASSERT_TRUE(sn && sf);
  auto rms = [](const std::vector<SdResidual>& v) {
    double s = 0;
    for (const auto& r : v) s += r.code_m * r.code_m;
    return std::sqrt(s / v.size());
  };
  const double rn = rms(sd_residuals(*sn)), rf = rms(sd_residuals(*sf));
  // 600 ppm x 5 km = 3 m / sin(el) vs < 1 m of receiver noise. Measured 2026-12-05: 10.02 m vs 1.79 m (5.6×).
  EXPECT_GT(rf, 5.0 * rn);
}

TEST(GnssSim, BlundersAppearAtTheConfiguredRateAndAreRecorded) {
  constexpr double kRate = 0.01;
  const sim::Simulation s = run(test::kOpenSkyGnssYaml, kRate);
  ASSERT_GT(s.gnss.rover_sat_epochs, 5000);
  // Starts per satellite-epoch outside a running blunder (binomial; 4 sigma).
  const double eligible = static_cast<double>(s.gnss.rover_sat_epochs) - static_cast<double>(s.gnss.blunders.size()) +
                          s.gnss.blunder_events;
  const double expected = kRate * eligible, sd = std::sqrt(expected * (1 - kRate));
  EXPECT_NEAR(s.gnss.blunder_events, expected, 4.0 * sd);
  // Every recorded blunder is in the data: the residual equals the recorded error within the noise.
  const auto res = sd_residuals(s);
  std::map<std::pair<int64_t, int>, const SdResidual*> by;
  for (const auto& r : res) by[{r.t.ns(), r.sat.prn}] = &r;
  int checked = 0;
  for (const auto& b : s.gnss.blunders) {
    ASSERT_GE(std::abs(b.error_m), s.scenario.gnss.blunder_min_m);
    ASSERT_LE(std::abs(b.error_m), s.scenario.gnss.blunder_max_m);
    const auto it = by.find({b.t.ns(), b.sat.prn});
    if (it == by.end()) continue;  // not seen at the base
    EXPECT_LT(std::abs(it->second->code_m - b.error_m), 6.0 * it->second->sigma_code_m);
    ++checked;
  }
  EXPECT_GT(checked, 178 * 10 / 13);  // measured 2026-12-05: 178 blunders seen at the base (63 events)
}

// sim::receiver_weight_model: the filter's eq. W1–W2 weights that describe the simulated receiver (pednav montecarlo
// --receiver-weights). Code: the DLL thermal σ itself (W2 carries the squaring loss); Doppler: the simulated σ wherever
// the C/N0 is at or below the multipath reference; no elevation factor. Checked on the forest_walk receiver (0.3 Hz
// DLL, 0.5 chip) and on the defaults (1 Hz, 1 chip: 2.6× noisier).
TEST(GnssSim, ReceiverWeightModelReproducesTheSimulatedCodeAndDopplerNoise) {
  sim::GnssOptions forest;
  forest.cn0_zenith_dbhz = 49.0;
  forest.dll_bandwidth_hz = 0.3;
  forest.correlator_spacing_chips = 0.5;
  for (const sim::GnssOptions& o : {forest, sim::GnssOptions{}}) {
    const gnss::WeightModel w = sim::receiver_weight_model(o);
    EXPECT_EQ(w.elevation_weight, 0.0);
    EXPECT_EQ(w.cn0_ref_dbhz, o.cn0_zenith_dbhz);
    EXPECT_GT(w.code_squaring_loss, 0.0);
    for (double cn0 = 15.0; cn0 <= o.cn0_zenith_dbhz; cn0 += 1.0) {
      for (double el_deg : {15.0, 45.0, 90.0}) {
        EXPECT_NEAR(gnss::measurement_sigma(w, cn0, el_deg * kDegToRad, false) / sim::thermal_code_sigma_m(o, cn0), 1.0,
                    1e-12)
            << "C/N0 " << cn0 << " el " << el_deg;
        if (cn0 <= o.multipath_cn0_ref_dbhz) {
          EXPECT_NEAR(gnss::measurement_sigma(w, cn0, el_deg * kDegToRad, true), sim::doppler_sigma_mps(o, cn0), 1e-12);
        }
      }
    }
  }
  EXPECT_NEAR(sim::receiver_weight_model(sim::GnssOptions{}).code_sigma_zenith_m /
                  sim::receiver_weight_model(forest).code_sigma_zenith_m,
              std::sqrt(1.0 * 1.0 / (0.3 * 0.5)), 0.01);  // σ ∝ sqrt(B d)
}

TEST(Constellation, NominalGpsConstellationGeometry) {
  const GpsTime t0 = GpsTime::from_week_tow(2300, 3600.0);
  const auto nav = sim::nominal_gps_constellation(27, t0, t0.plus_s(86400.0), 5);
  std::map<int, int> records;
  for (const auto& e : nav.kepler) ++records[e.sat.prn];
  ASSERT_EQ(records.size(), 27u);
  const Eigen::Vector3d p_user = ecef_from_geodetic({51.08 * kDegToRad, -114.13 * kDegToRad, 1000.0});
  int min_visible = 99;
  for (double dt = 0; dt <= 86400.0; dt += 600.0) {
    const GpsTime t = t0.plus_s(dt);
    int visible = 0;
    for (const auto& [prn, n] : records) {
      auto s = gnss::satellite_state(nav, {gnss::System::kGps, prn}, t);
      ASSERT_TRUE(s.has_value());
      EXPECT_NEAR(s->p_es_e.norm(), 26559.7e3, 400e3);  // GPS orbit radius (e <= 0.012)
      if (gnss::elevation_azimuth(p_user, s->p_es_e).elevation > 10.0 * kDegToRad) ++visible;
    }
    min_visible = std::min(min_visible, visible);
  }
  EXPECT_GE(min_visible, 5);  // a 24+ slot constellation always shows >= 5 above 10 deg at mid latitudes
  // Records of one satellite describe one orbit: states from two neighbouring records agree at their midpoint.
  const auto& e0 = nav.kepler[0];
  const auto& e1 = nav.kepler[1];
  ASSERT_EQ(e0.sat, e1.sat);
  const GpsTime mid = GpsTime::from_ns((e0.toe.ns() + e1.toe.ns()) / 2);
  EXPECT_LT((gnss::kepler_satellite_state(e0, mid).p_es_e - gnss::kepler_satellite_state(e1, mid).p_es_e).norm(), 1e-3);
}

TEST(GnssSim, OpenSkyStartHasSevenSatellitesInTheForestScenarioTime) {
  // The forest_walk start epoch shows >= 7 satellites above 5 degrees (seed 004: SiRF tracked >= 7).
  const GpsTime t0 = GpsTime::from_week_tow(2300, 225000.0);
  const auto nav = sim::nominal_gps_constellation(27, t0, t0.plus_s(1100.0), 4);
  const Eigen::Vector3d p_user = ecef_from_geodetic({51.08 * kDegToRad, -114.13 * kDegToRad, 1050.0});
  for (double dt = 0; dt <= 1080.0; dt += 60.0) {
    int visible = 0;
    for (int prn = 1; prn <= 27; ++prn) {
      auto s = gnss::satellite_state(nav, {gnss::System::kGps, prn}, t0.plus_s(dt));
      if (s && gnss::elevation_azimuth(p_user, s->p_es_e).elevation > 5.0 * kDegToRad) ++visible;
    }
    EXPECT_GE(visible, 7) << "at " << dt << " s";
  }
}

}  // namespace
}  // namespace pednav
