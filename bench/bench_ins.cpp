// SPDX-License-Identifier: BSD-2-Clause
// Benchmarks of the INS hot paths (issue 12): one mechanization step, increment integration per IMU sample,
// the error-model discretization, and the IMU CSV parser (lines per second).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/geodesy.hpp"
#include "ins/alignment.hpp"
#include "ins/error_state.hpp"
#include "ins/mechanization.hpp"
#include "io/imu_csv.hpp"

namespace {

using namespace pednav;

std::vector<ins::ImuSample> samples(int n, double rate_hz) {
  std::vector<ins::ImuSample> s(n);
  for (int i = 0; i < n; ++i) {
    const double t = i / rate_hz;
    s[i].t = GpsTime::from_ns(std::llround(t * 1e9));
    s[i].omega_ib_b = Eigen::Vector3d(0.3 * std::sin(7 * t), 5.0 * std::sin(6 * t), 0.2 * std::cos(5 * t));
    s[i].f_ib_b = Eigen::Vector3d(3 * std::sin(6 * t), 1.0, -9.8 + 4 * std::cos(6 * t));
  }
  return s;
}

void BM_MechanizationStep(benchmark::State& st) {
  const auto incs = ins::integrate_all(samples(401, 400.0), {20.0, true, true});
  ins::NavState s = ins::nav_state_at_rest(GpsTime(), ecef_from_geodetic({0.9, -2.0, 1000.0}), 0.1, 0.2, 0.3);
  size_t k = 0;
  for (auto _ : st) {
    s = ins::mechanize(s, incs[k++ % incs.size()]);
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_MechanizationStep);

void BM_IncrementIntegrationPerSample(benchmark::State& st) {
  const auto s = samples(4000, 400.0);
  ins::IncrementIntegrator integ({20.0, true, true});
  int64_t offset = 0;
  size_t k = 0;
  Eigen::Vector3d sink = Eigen::Vector3d::Zero();
  for (auto _ : st) {
    ins::ImuSample x = s[k];
    x.t = x.t.plus_ns(offset);
    integ.push(x, [&](const ins::ImuIncrement& inc) { sink += inc.dv_b; });
    if (++k == s.size()) {
      k = 0;
      offset += 10'000'000'000LL;
    }
  }
  benchmark::DoNotOptimize(sink);
  st.SetItemsProcessed(st.iterations());
}
BENCHMARK(BM_IncrementIntegrationPerSample);

void BM_ErrorModelDiscretize15(benchmark::State& st) {
  const ins::ErrorStateLayout layout;
  const auto spec = *ins::imu_spec_preset("crista");
  const auto incs = ins::integrate_all(samples(41, 400.0), {20.0, true, true});
  const ins::NavState a = ins::nav_state_at_rest(GpsTime(), ecef_from_geodetic({0.9, -2.0, 1000.0}), 0.1, 0.2, 0.3);
  const ins::NavState b = ins::mechanize(a, incs[0]);
  for (auto _ : st) benchmark::DoNotOptimize(ins::interval_error_model(layout, spec, a, b, incs[0]));
}
BENCHMARK(BM_ErrorModelDiscretize15);

void BM_ImuCsvParse(benchmark::State& st) {
  std::string text = "Time (s),gx,gy,gz,ax,ay,az\n";
  char line[160];
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    std::snprintf(line, sizeof line, "%.9f,%.7f,%.7f,%.7f,%.7f,%.7f,%.7f\n", i * 0.0025, 0.1 * std::sin(i * 0.01),
                  -0.7 + 0.01 * std::cos(i * 0.02), 0.2, -0.4937814, 0.2420433, 0.8312204 + 1e-4 * std::sin(i * 0.3));
    text += line;
  }
  io::ImuFormat f;
  f.gyro_unit = "deg_per_s";
  f.accel_unit = "g";
  for (auto _ : st) {
    auto log = io::parse_imu_csv(text.data(), text.size(), "bench.csv", f);
    if (!log) st.SkipWithError(log.error().message.c_str());
    benchmark::DoNotOptimize(log);
  }
  st.SetItemsProcessed(st.iterations() * n);  // items/s = lines/s
  st.SetBytesProcessed(st.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_ImuCsvParse)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
