// SPDX-License-Identifier: BSD-2-Clause
#include "gnss/code_smoothing.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace pednav::gnss {
namespace {

struct SatFilter {
  GpsTime t;                    // epoch of the last update
  double smoothed_m = 0.0;      // P̃ at t
  double doppler_hz = 0.0;      // D at t
  double wavelength_m = 0.0;
  int n = 0;                    // epochs since the (re)start
};

bool usable(const SatObs& s) {
  return std::isfinite(s.pseudorange_m) && std::isfinite(s.doppler_hz) && std::isfinite(s.wavelength_m) &&
         s.wavelength_m > 0.0;
}

double median(std::vector<double> v) {
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(m), v.end());
  if (v.size() % 2 == 1) return v[m];
  const double hi = v[m];
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + static_cast<long>(m)));
}

}  // namespace

CodeSmoothingStats smooth_code_with_doppler(std::vector<ObsEpoch>& epochs, const CodeSmoothingOptions& o) {
  CodeSmoothingStats stats;
  if (!(o.window_s > 0.0) || epochs.size() < 2) return stats;
  std::map<SatId, SatFilter> filters;
  for (ObsEpoch& e : epochs) {
    // Prediction of each running filter to this epoch and the code's departure from it.
    std::vector<double> predicted(e.sats.size(), NAN), departures;
    for (size_t i = 0; i < e.sats.size(); ++i) {
      const SatObs& s = e.sats[i];
      auto it = filters.find(s.sat);
      if (it == filters.end() || !usable(s)) continue;
      const SatFilter& f = it->second;
      const double dt = e.time - f.t;
      if (!(dt > 0.0) || dt > o.max_gap_s) continue;
      predicted[i] = f.smoothed_m - 0.5 * (f.wavelength_m * f.doppler_hz + s.wavelength_m * s.doppler_hz) * dt;
      departures.push_back(s.pseudorange_m - predicted[i]);
    }
    // A receiver clock jump (e.g. 1 ms = 300 km) steps every code but no Doppler: carry it into every filter.
    double common_m = 0.0;
    if (!departures.empty()) {
      const double med = median(departures);
      if (std::abs(med) > o.clock_jump_m) {
        common_m = med;
        ++stats.clock_jumps;
      }
    }
    for (size_t i = 0; i < e.sats.size(); ++i) {
      SatObs& s = e.sats[i];
      if (!usable(s)) {
        if (filters.erase(s.sat) > 0) ++stats.restarts_gap;
        continue;
      }
      SatFilter& f = filters[s.sat];
      const bool running = std::isfinite(predicted[i]);
      if (running && std::abs(s.pseudorange_m - predicted[i] - common_m) <= o.reset_threshold_m) {
        const double dt = e.time - f.t;
        const int n_max = std::max(1, static_cast<int>(std::lround(o.window_s / dt)));
        f.n = std::min(f.n + 1, n_max);
        const double w = 1.0 / f.n;
        f.smoothed_m = w * s.pseudorange_m + (1.0 - w) * (predicted[i] + common_m);
        s.pseudorange_m = f.smoothed_m;
        ++stats.smoothed;
      } else {
        if (running) ++stats.restarts_jump;
        else if (f.n > 0) ++stats.restarts_gap;
        f.n = 1;
        f.smoothed_m = s.pseudorange_m;
      }
      f.t = e.time;
      f.doppler_hz = s.doppler_hz;
      f.wavelength_m = s.wavelength_m;
    }
  }
  return stats;
}

}  // namespace pednav::gnss
