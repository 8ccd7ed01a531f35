// SPDX-License-Identifier: BSD-2-Clause
// Benchmarks of the fusion hot paths (issue 10): covariance prediction of one mechanization step, a ZUPT (+ZARU)
// update, an SD pseudorange + Doppler update with 10 satellites, one smoother step (the earlier per-step backward
// map, and the interval bookkeeping the engine runs now), and reading a RINEX
// observation file (epochs per second). Error state n = 17 (15 INS + one clock + drift, as `pednav run` with GPS).
// Every benchmark also reports `allocs_per_iter`, the heap allocations per iteration counted by a replaced
// global operator new (docs/performance.md "Heap allocations").
#include <benchmark/benchmark.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <random>
#include <string>

#include "core/row_transition.hpp"
#include "core/geodesy.hpp"
#include "fusion/engine.hpp"
#include "fusion/stance_updates.hpp"
#include "fusion/kalman.hpp"
#include "fusion/rts.hpp"
#include "gnss/least_squares.hpp"
#include "gnss/measurement.hpp"
#include "gnss/rtklib/rinex.hpp"
#include "ins/alignment.hpp"
#include "ins/error_state.hpp"
#include "ins/imu_spec.hpp"
#include "ins/mechanization.hpp"
#include "io/rinex_writer.hpp"
#include "sim/constellation.hpp"

// Allocation counter: every global operator new of this executable goes through here.
#include "tests/support/counting_new.hpp"

namespace {

using namespace pednav;
using ins::ErrorMatrix;
using ins::ErrorVector;

// Allocations per iteration over the timed loop.
struct AllocCounter {
  long start = g_allocs.load();
  void report(benchmark::State& st) const {
    st.counters["allocs_per_iter"] =
        static_cast<double>(g_allocs.load() - start) / static_cast<double>(std::max<int64_t>(1, st.iterations()));
  }
};

ins::ErrorStateLayout layout17() {
  ins::ErrorStateLayout l;
  (void)l.add("clock_0", 1);
  (void)l.add("drift", 1);
  return l;
}

ErrorMatrix random_spd(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nd;
  Eigen::MatrixXd L(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) L(i, j) = nd(rng);
  return ErrorMatrix(L * L.transpose() / n + 0.1 * Eigen::MatrixXd::Identity(n, n));
}

ins::ImuIncrement increment() {
  ins::ImuIncrement inc;
  inc.t1 = GpsTime::from_ns(50'000'000);
  inc.dt_s = 0.05;
  inc.samples = 5;
  inc.alpha_b = inc.dtheta_b = Eigen::Vector3d(0.01, 0.2, -0.005);
  inc.upsilon_b = inc.dv_b = Eigen::Vector3d(0.1, 0.02, -0.49);
  inc.dp_b = inc.dv_b * 0.025;
  return inc;
}

// Covariance prediction of one mechanization step as the engine does it: the discrete error model of the interval
// (F, G, Q → Φ, Q_d) and P ← Φ P Φᵀ + Q_d.
void BM_CovariancePrediction17(benchmark::State& st) {
  ins::ErrorStateLayout layout = layout17();
  if (st.range(0) > layout.dim()) (void)layout.add("multipath", static_cast<int>(st.range(0)) - layout.dim());
  const auto spec = *ins::imu_spec_preset("crista");
  const ins::NavState a = ins::nav_state_at_rest(GpsTime(), ecef_from_geodetic({0.9, -2.0, 1000.0}), 0.1, 0.2, 0.3);
  const ins::ImuIncrement inc = increment();
  const ins::NavState b = ins::mechanize(a, inc);
  ErrorMatrix P = random_spd(layout.dim(), 1u), tmp;
  const ErrorMatrix P0 = P;
  RowTransition<ins::kMaxErrorDim> Phi;
  AllocCounter allocs;
  for (auto _ : st) {
    const ins::DiscreteErrorModel m = ins::interval_error_model(layout, spec, a, b, inc);
    Phi.assign(m.Phi);  // as the engine: Φ by its row structure
    fusion::covariance_predict(P, Phi, m.Qd, tmp);
    if (P(0, 0) > 1e6) P = P0;
    benchmark::DoNotOptimize(P.data());
  }
  allocs.report(st);
}
// The argument is n; 29 = 17 + 12 code-multipath states (the default, docs/consistency.md §3.1).
BENCHMARK(BM_CovariancePrediction17)->Arg(17)->Arg(29);

// P ← Φ P Φᵀ + Q_d alone (17 states).
void BM_CovariancePropagationOnly17(benchmark::State& st) {
  const int n = 17;
  const ErrorMatrix Phi = ErrorMatrix::Identity(n, n) + 0.01 * random_spd(n, 2u);
  const ErrorMatrix Qd = 1e-6 * random_spd(n, 3u);
  ErrorMatrix P = random_spd(n, 1u), tmp;
  const ErrorMatrix P0 = P;
  AllocCounter allocs;
  for (auto _ : st) {
    fusion::covariance_predict(P, Phi, Qd, tmp);
    if (P(0, 0) > 1e6) P = P0;
    benchmark::DoNotOptimize(P.data());
  }
  allocs.report(st);
}
BENCHMARK(BM_CovariancePropagationOnly17);

// ZUPT form D (3 rows) + ZARU (3 rows) Joseph update on 17 states, as the engine's stance epochs.
using H6 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, ins::kMaxErrorDim>;
using R6 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 6, 6>;
using V6 = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 6, 1>;

// The 6 rows of a stance update (form-D ZUPT at foot velocity v + ZARU) for an n-state layout: H, residual, R.
void zupt_rows(int n, const Eigen::Vector3d& v, H6& H, V6& r, R6& R) {
  H = H6::Zero(6, n);
  const Eigen::Matrix<double, 3, 6> J = fusion::zupt_jacobian(v, fusion::ZuptForm::kDynamic);
  H.block<3, 3>(0, ins::kVel.offset) = J.leftCols<3>();
  H.block<3, 3>(0, ins::kAtt.offset) = J.rightCols<3>();
  H.block<3, 3>(3, ins::kBiasGyro.offset).setIdentity();
  r.resize(6);
  r << -v, 1e-4, -2e-4, 5e-5;
  R = R6::Zero(6, 6);
  R.diagonal() << 4e-4, 4e-4, 4e-4, 1e-4, 1e-4, 1e-4;
}

void BM_ZuptUpdate(benchmark::State& st) {
  const int n = static_cast<int>(st.range(0));
  const ErrorMatrix P0 = random_spd(n, 4u);
  ErrorMatrix P = P0;
  ErrorVector dx;
  const Eigen::Vector3d v(0.01, -0.02, 0.005);
  AllocCounter allocs;
  for (auto _ : st) {
    H6 H;
    V6 r;
    R6 R;
    zupt_rows(n, v, H, r, R);
    P = P0;
    benchmark::DoNotOptimize(fusion::joseph_update(P, H, r, R, dx));
    benchmark::DoNotOptimize(dx.data());
  }
  allocs.report(st);
}
BENCHMARK(BM_ZuptUpdate)->Arg(17)->Arg(29);  // 29: + 12 code-multipath states (the default)

// SD pseudorange + SD Doppler update with 10 satellites: satellite states at the rover and base transmit times,
// the SD models with Jacobians, weights, the w-test (S⁻¹) and the 20-row Joseph update, with the same library
// calls and matrix types as the engine's GNSS epoch.
void BM_SdCodeDopplerUpdate10(benchmark::State& st) {
  const GpsTime t = GpsTime::from_week_tow(2300, 226000.0);
  const gnss::NavData nav = sim::nominal_gps_constellation(27, t.plus_ns(-3'600'000'000'000LL), t.plus_ns(3'600'000'000'000LL), 1u);
  const Eigen::Vector3d p_base = ecef_from_geodetic({51.08 * kDegToRad, -114.13 * kDegToRad, 1050.0});
  const Eigen::Vector3d p_rover = p_base + Eigen::Vector3d(30.0, -40.0, 10.0);
  const Eigen::Vector3d v_rover(0.5, 1.0, 0.0);
  struct Sat {
    gnss::SatId id;
    double pr_r, pr_b, rr_r, rr_b;
  };
  std::vector<Sat> sats;
  for (int prn = 1; prn <= 32 && sats.size() < 10; ++prn) {
    const gnss::SatId id{gnss::System::kGps, prn};
    auto s = gnss::satellite_state(nav, id, t);
    if (!s || gnss::elevation_azimuth(p_rover, s->p_es_e).elevation < 10.0 * kDegToRad) continue;
    const double rho_r = (s->p_es_e - p_rover).norm(), rho_b = (s->p_es_e - p_base).norm();
    sats.push_back({id, rho_r + 30.0, rho_b + 10.0, -100.0, -101.0});
  }
  if (sats.size() < 10) {
    st.SkipWithError("fewer than 10 satellites above 10 deg");
    return;
  }
  const int n = 17, m = 20, clock = 15, drift = 16;
  const ErrorMatrix P0 = random_spd(n, 5u);
  ErrorMatrix P = P0;
  ErrorVector dx;
  const gnss::WeightModel w;
  constexpr int kMax = 64;
  using HM = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMax, ins::kMaxErrorDim>;
  using RM = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMax, kMax>;
  using RV = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMax, 1>;
  const double threshold = gnss::chi_square_quantile(0.999, 1);
  AllocCounter allocs;
  for (auto _ : st) {
    HM H = HM::Zero(m, n);
    RV r(m);
    RM R = RM::Zero(m, m);
    int row = 0;
    for (const Sat& s : sats) {
      gnss::SignalAtReceiver rs, bs;
      rs.pseudorange_m = s.pr_r;
      rs.range_rate_mps = s.rr_r;
      bs.pseudorange_m = s.pr_b;
      bs.range_rate_mps = s.rr_b;
      auto sr = gnss::satellite_state_at_reception(nav, s.id, t, s.pr_r);
      auto sb = gnss::satellite_state_at_reception(nav, s.id, t, s.pr_b);
      if (!sr || !sb) continue;
      rs.sat = *sr;
      bs.sat = *sb;
      const double el = gnss::elevation_azimuth(p_rover, sr->p_es_e).elevation;
      const gnss::MeasurementRow code = gnss::sd_pseudorange(s.id, rs, bs, p_rover, p_base, 0.0);
      const gnss::MeasurementRow rate = gnss::sd_range_rate(s.id, rs, bs, p_rover, v_rover, p_base, 0.0);
      H.block<1, 3>(row, ins::kPos.offset) = code.J_p;
      H(row, clock) = code.J_clock;
      r(row) = code.residual;
      R(row, row) = std::pow(gnss::measurement_sigma(w, 40.0, el, false), 2) * 2.0;
      ++row;
      H.block<1, 3>(row, ins::kPos.offset) = rate.J_p;
      H.block<1, 3>(row, ins::kVel.offset) = rate.J_v;
      H(row, drift) = rate.J_drift;
      r(row) = rate.residual;
      R(row, row) = std::pow(gnss::measurement_sigma(w, 40.0, el, true), 2) * 2.0;
      ++row;
    }
    // w-test: S⁻¹ once (no rejection here), then the update.
    RM S = R;
    S.noalias() += H * P0 * H.transpose();
    const RM Sinv = S.ldlt().solve(RM::Identity(m, m));
    const RV a = Sinv * r;
    int worst = -1;
    for (int i = 0; i < m; ++i) {
      if (a(i) * a(i) / Sinv(i, i) > threshold) worst = i;
    }
    benchmark::DoNotOptimize(worst);
    P = P0;
    benchmark::DoNotOptimize(fusion::joseph_update(P, H, r, R, dx));
  }
  allocs.report(st);
}
BENCHMARK(BM_SdCodeDopplerUpdate10);

// One smoother step at an update epoch: the backward map (Jacobi-scaled LDLT solve for C, eq. 12.4-12.7) and its
// composition into the output-epoch segment (eq. 12.9).
void BM_SmootherStep(benchmark::State& st) {
  const int n = 17;
  const ErrorMatrix P_post = random_spd(n, 6u);
  const ErrorMatrix Phi = ErrorMatrix::Identity(n, n) + 0.01 * random_spd(n, 7u);
  ErrorMatrix P_prior = Phi * P_post * Phi.transpose() + 1e-4 * random_spd(n, 8u);
  const ErrorMatrix A = ErrorMatrix::Identity(n, n);
  const ErrorVector d = 0.01 * ErrorVector::Ones(n);
  fusion::RtsAccumulator acc(n);
  fusion::RtsStep step;
  AllocCounter allocs;
  for (auto _ : st) {
    fusion::rts_step(P_post, Phi, P_prior, A, d, step);
    acc.append(step);
    if (acc.steps() == 20) benchmark::DoNotOptimize(acc.take());
  }
  allocs.report(st);
}
BENCHMARK(BM_SmootherStep);

// The smoother's bookkeeping of one stance step as the engine does it since the interval recursion (docs/fusion.md
// eqs. 12.15-12.17): the cross-covariance prediction Γ Φᵀ with Φ of the INS error model by its non-zeros, and the
// ZUPT form D + ZARU update (6 rows, the filter's S factorization and gain); the interval is closed (M = Γ P⁻¹,
// eq. 12.20) and restarted every 20 iterations (1 Hz output at 20 Hz). Per iteration the counterpart of
// BM_SmootherStep (which the earlier engine ran at every stance step).
void BM_SmootherIntervalStep(benchmark::State& st) {
  ins::ErrorStateLayout layout = layout17();
  if (st.range(0) > layout.dim()) (void)layout.add("multipath", static_cast<int>(st.range(0)) - layout.dim());
  const int n = layout.dim();
  const auto spec = *ins::imu_spec_preset("crista");
  const ins::NavState a = ins::nav_state_at_rest(GpsTime(), ecef_from_geodetic({0.9, -2.0, 1000.0}), 0.1, 0.2, 0.3);
  const ins::ImuIncrement inc = increment();
  const ins::NavState b = ins::mechanize(a, inc);
  const ins::DiscreteErrorModel model = ins::interval_error_model(layout, spec, a, b, inc);
  RowTransition<ins::kMaxErrorDim> Phi;
  Phi.assign(model.Phi);
  const ErrorMatrix P = random_spd(n, 4u);
  using K6 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, ins::kMaxErrorDim, 6>;
  const Eigen::Vector3d v(0.01, -0.02, 0.005);
  H6 H;
  V6 r;
  R6 S;
  zupt_rows(n, v, H, r, S);
  S.noalias() += H * P * H.transpose();
  const Eigen::LDLT<R6> ldlt(S);
  const K6 K = ldlt.solve(H * P).transpose();
  fusion::RtsInterval interval(n);
  interval.restart(P);
  fusion::RtsSegment seg;
  int k = 0;
  AllocCounter allocs;
  for (auto _ : st) {
    interval.predict(Phi);
    interval.update(H, r, ldlt, K);
    if (++k == 20) {
      interval.close(P, seg);
      interval.restart(P);
      k = 0;
      benchmark::DoNotOptimize(seg.M.data());
    }
  }
  allocs.report(st);
}
BENCHMARK(BM_SmootherIntervalStep)->Arg(17)->Arg(29);

// Reading a RINEX 3.04 observation file (1 Hz, 10 GPS satellites with C1C/D1C/S1C) through the RTKLIB adapter:
// items/s = epochs per second.
void BM_RinexObsRead(benchmark::State& st) {
  const int epochs = 3600;
  gnss::ObsData obs;
  const GpsTime t0 = GpsTime::from_week_tow(2300, 226000.0);
  for (int k = 0; k < epochs; ++k) {
    gnss::ObsEpoch e;
    e.time = t0.plus_ns(static_cast<int64_t>(k) * 1'000'000'000LL);
    for (int prn = 1; prn <= 10; ++prn) {
      gnss::SatObs s;
      s.sat = {gnss::System::kGps, prn * 3};
      s.pseudorange_m = 2.1e7 + 1e5 * prn + 100.0 * k;
      s.doppler_hz = -500.0 + 10.0 * prn;
      s.cn0_dbhz = 40.0 + prn % 7;
      e.sats.push_back(s);
    }
    obs.epochs.push_back(e);
  }
  const std::string path = (std::filesystem::temp_directory_path() / "pednav_bench_rinex.obs").string();
  if (auto ok = io::write_rinex_obs(path, obs, {}); !ok) {
    st.SkipWithError(ok.error().message.c_str());
    return;
  }
  for (auto _ : st) {
    auto r = gnss::read_rinex_obs(path, {});
    if (!r || r->epochs.size() != static_cast<size_t>(epochs)) st.SkipWithError("RINEX read failed");
    benchmark::DoNotOptimize(r);
  }
  st.SetItemsProcessed(st.iterations() * epochs);
  std::filesystem::remove(path);
}
BENCHMARK(BM_RinexObsRead)->Unit(benchmark::kMillisecond);

}  // namespace
