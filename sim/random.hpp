// SPDX-License-Identifier: BSD-2-Clause
// Deterministic random numbers for the simulator: xoshiro256** (Blackman & Vigna 2018) seeded through
// splitmix64, normal deviates by the Marsaglia polar method. Self-contained so that the same seed gives the
// same numbers on every platform and standard library (std::normal_distribution is implementation-defined).
#pragma once

#include <cmath>
#include <algorithm>
#include <cstdint>

namespace pednav::sim {

/// A seeded random stream. Independent streams come from stream(seed, id): each model (gait, IMU errors,
/// rover GNSS, base GNSS, ...) draws from its own, so changing one model leaves the others' numbers unchanged.
class Rng {
 public:
  /// Stream `stream_id` of the scenario seed.
  Rng(uint64_t seed, uint64_t stream_id) {
    uint64_t x = seed ^ (0x9E3779B97F4A7C15ULL * (stream_id + 1));
    for (auto& s : s_) s = splitmix64(x);
  }
  /// Next raw 64-bit value.
  uint64_t next() {
    const uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Standard normal deviate (Marsaglia polar method; the second deviate of each pair is kept).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u = 0.0, v = 0.0, s = 0.0;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double m = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * m;
    has_spare_ = true;
    return u * m;
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static uint64_t splitmix64(uint64_t& x) {
    uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  uint64_t s_[4]{};
  bool has_spare_ = false;
  double spare_ = 0.0;
};

/// Stream ids of the simulator's models (fixed: reordering them would change every scenario's output).
enum StreamId : uint64_t {
  kStreamGait = 1,
  kStreamImu = 2,
  kStreamRover = 3,
  kStreamBase = 4,
  kStreamConstellation = 5,
  kStreamClocks = 6,
  kStreamBlunders = 7,
  kStreamAtmosphere = 8,
  kStreamCarrierRover = 9,  ///< carrier phase of the rover: ambiguities, PLL noise, multipath, slips (docs/sim.md §8)
  kStreamCarrierBase = 10,  ///< the same for the base
};

/// First-order Gauss-Markov process with unit steady-state variance, sampled at steps dt_s (exact
/// discretization: x <- phi x + sqrt(1 - phi^2) w, phi = exp(-dt/tau); Gelb 1974 §4.3). Scale by the
/// (possibly time-varying) sigma at use.
class UnitGaussMarkov {
 public:
  UnitGaussMarkov() = default;
  /// Starts in steady state (x0 ~ N(0, 1)).
  UnitGaussMarkov(double tau_s, Rng& rng) : tau_s_(tau_s), x_(rng.normal()) {}
  /// Advance by dt_s [s] and return the new value.
  double step(double dt_s, Rng& rng) {
    const double phi = tau_s_ > 0.0 ? std::exp(-dt_s / tau_s_) : 0.0;
    x_ = phi * x_ + std::sqrt(std::max(0.0, 1.0 - phi * phi)) * rng.normal();
    return x_;
  }
  double value() const { return x_; }

 private:
  double tau_s_ = 1.0;
  double x_ = 0.0;
};

}  // namespace pednav::sim
