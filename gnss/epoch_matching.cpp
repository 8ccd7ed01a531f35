// SPDX-License-Identifier: BSD-2-Clause
// Rover/base epoch matching; see gnss/epoch_matching.hpp.
#include "gnss/epoch_matching.hpp"

#include <algorithm>
#include <cmath>

namespace pednav::gnss {

std::vector<BaseMatch> match_base_epochs(const std::vector<GpsTime>& rover_times,
                                         const std::vector<GpsTime>& base_times, double max_age_s) {
  std::vector<BaseMatch> out(rover_times.size());
  size_t j = 0;  // first base epoch not before the current rover epoch (both lists ascend)
  for (size_t i = 0; i < rover_times.size(); ++i) {
    const GpsTime t = rover_times[i];
    while (j < base_times.size() && base_times[j] < t) ++j;
    int best = -1;
    double best_abs = 1e300;
    for (size_t k : {j == 0 ? size_t(-1) : j - 1, j}) {
      if (k >= base_times.size()) continue;
      const double a = std::abs(t - base_times[k]);
      if (a < best_abs) best_abs = a, best = static_cast<int>(k);
    }
    if (best >= 0 && best_abs <= max_age_s) out[i] = BaseMatch{best, t - base_times[best]};
  }
  return out;
}

ObsEpoch propagate_base_with_doppler(const ObsEpoch& base, GpsTime t) {
  ObsEpoch out;
  out.time = t;
  const double dt = t - base.time;
  for (const SatObs& s : base.sats) {
    if (std::isnan(s.doppler_hz) || std::isnan(s.pseudorange_m)) continue;
    SatObs p = s;
    p.pseudorange_m = s.pseudorange_m - s.wavelength_m * s.doppler_hz * dt;
    p.carrier_cycles = s.carrier_cycles - s.doppler_hz * dt;  // Φ̇ = −D (docs/carrier.md §5); NaN stays NaN
    out.sats.push_back(p);
  }
  return out;
}

AgeStats age_statistics(const std::vector<BaseMatch>& matches, double tolerance_s) {
  AgeStats st;
  std::vector<double> ages;
  for (const BaseMatch& m : matches) {
    if (m.base_index < 0) { ++st.unmatched; continue; }
    const double a = std::abs(m.age_s);
    ages.push_back(a);
    const double edges[] = {tolerance_s, 1.0, 2.0, 5.0, 10.0, 30.0};
    int bin = 6;
    for (int b = 0; b < 6; ++b) {
      if (a <= edges[b]) { bin = b; break; }
    }
    ++st.histogram[bin];
    st.simultaneous += a <= tolerance_s;
  }
  st.matched = static_cast<int>(ages.size());
  if (ages.empty()) return st;
  std::sort(ages.begin(), ages.end());
  double sum = 0.0;
  for (double a : ages) sum += a;
  st.mean_s = sum / ages.size();
  st.median_s = ages[ages.size() / 2];
  st.p95_s = ages[std::min(ages.size() - 1, static_cast<size_t>(std::ceil(0.95 * ages.size())) - 1)];
  st.max_s = ages.back();
  return st;
}

}  // namespace pednav::gnss
