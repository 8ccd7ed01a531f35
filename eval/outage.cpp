// SPDX-License-Identifier: BSD-2-Clause
#include "eval/outage.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace pednav::eval {

Expected<std::vector<OutageWindow>> place_windows_evenly(GpsTime from, GpsTime to, int count, double duration_s) {
  if (count < 1) return make_error("outage windows: count must be >= 1, got " + std::to_string(count));
  if (!(duration_s > 0.0)) return make_error("outage windows: duration must be > 0 s");
  const double span_s = to - from;
  const double slot_s = span_s / count;
  if (!(slot_s >= duration_s)) {
    std::ostringstream m;
    m << "outage windows: " << count << " x " << duration_s << " s do not fit in the " << std::max(0.0, span_s)
      << " s between convergence (" << from.to_string() << ") and the end of the run (" << to.to_string() << ")";
    return make_error(m.str());
  }
  std::vector<OutageWindow> w;
  for (int k = 0; k < count; ++k) {
    // Centre of slot k, rounded to whole seconds so that 1 Hz outputs fall on the same offsets in every window.
    const double start_s = std::round(k * slot_s + 0.5 * (slot_s - duration_s));
    w.push_back({from.plus_s(start_s), duration_s});
  }
  return w;
}

double ReferenceCoverage::covered_s(GpsTime start, GpsTime end) const {
  double covered = 0.0;
  // The first epoch pair that can reach into [start, end]: the one starting at the last epoch before `start`.
  auto it = std::lower_bound(epochs.begin(), epochs.end(), start);
  if (it != epochs.begin()) --it;
  for (; it != epochs.end() && std::next(it) != epochs.end() && *it < end; ++it) {
    const GpsTime a = *it, b = *std::next(it);
    if (b - a > max_gap_s) continue;
    const GpsTime lo = a < start ? start : a, hi = end < b ? end : b;
    if (lo < hi) covered += hi - lo;
  }
  return covered;
}

Expected<std::vector<OutageWindow>> place_windows_covered(GpsTime from, GpsTime to, int count, double duration_s,
                                                          const ReferenceCoverage& reference) {
  auto centred = place_windows_evenly(from, to, count, duration_s);
  if (!centred) return centred;
  const double slot_s = (to - from) / count;
  std::vector<OutageWindow> w;
  for (int k = 0; k < count; ++k) {
    const double centre_s = (*centred)[static_cast<size_t>(k)].start - from;
    // Whole-second starts (as the centred ones) with the window inside slot k.
    const double first_s = std::ceil(k * slot_s), last_s = std::floor((k + 1) * slot_s - duration_s);
    double best_s = centre_s;
    double best_cover = reference.covered_s(from.plus_s(centre_s), from.plus_s(centre_s + duration_s));
    for (double s = first_s; s <= last_s; s += 1.0) {
      const double cover = reference.covered_s(from.plus_s(s), from.plus_s(s + duration_s));
      // 1 ms: coverage sums of different windows are compared as equal below it (whole-second epochs).
      constexpr double kSameCover_s = 1e-3;
      if (cover > best_cover + kSameCover_s ||
          (std::abs(cover - best_cover) <= kSameCover_s && std::abs(s - centre_s) < std::abs(best_s - centre_s))) {
        best_s = s;
        best_cover = cover;
      }
    }
    w.push_back({from.plus_s(best_s), duration_s});
  }
  return w;
}

Expected<std::vector<OutageWindow>> explicit_windows(std::vector<GpsTime> starts, double duration_s) {
  if (starts.empty()) return make_error("outage windows: no start time given");
  if (!(duration_s > 0.0)) return make_error("outage windows: duration must be > 0 s");
  std::vector<OutageWindow> w;
  for (size_t k = 0; k < starts.size(); ++k) {
    if (k > 0 && starts[k] - starts[k - 1] < duration_s) {
      return make_error("outage windows: start " + starts[k].to_string() + " is less than the duration (" +
                        std::to_string(duration_s) + " s) after the previous start " + starts[k - 1].to_string() +
                        " (windows must be increasing and not overlap)");
    }
    w.push_back({starts[k], duration_s});
  }
  return w;
}

std::vector<int> select_kept_satellites(std::vector<SatCandidate> candidates, int keep, KeepBy by) {
  if (keep <= 0) return {};
  auto key = [by](const SatCandidate& c) {
    const double v = by == KeepBy::kElevation ? c.elevation_rad : c.cn0_dbhz;
    return std::isnan(v) ? -1e300 : v;
  };
  // Dropping the lowest while more than `keep` remain == keeping the `keep` highest.
  std::sort(candidates.begin(), candidates.end(), [&](const SatCandidate& a, const SatCandidate& b) {
    const double ka = key(a), kb = key(b);
    return ka != kb ? ka > kb : a.id < b.id;
  });
  if (static_cast<int>(candidates.size()) > keep) candidates.resize(static_cast<size_t>(keep));
  std::vector<int> ids;
  for (const auto& c : candidates) ids.push_back(c.id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

WindowStats window_stats(const WindowErrors& w) {
  WindowStats s;
  s.samples = static_cast<int>(w.horizontal_m.size());
  const bool have_sigma = w.sigma_horizontal_m.size() == w.horizontal_m.size();
  for (size_t i = 0; i < w.horizontal_m.size(); ++i) {
    if (i == 0 || w.horizontal_m[i] > s.max_m) {
      s.max_m = w.horizontal_m[i];
      if (have_sigma) s.sigma_at_max_m = w.sigma_horizontal_m[i];
    }
  }
  if (s.samples > 0) {
    s.end_m = w.horizontal_m.back();
    s.end_t_since_s = w.t_since_s.back();
    if (have_sigma) s.end_sigma_m = w.sigma_horizontal_m.back();
  }
  return s;
}

RmsVsTime rms_vs_time(const std::vector<WindowErrors>& windows, double bin_s) {
  // bin -> (sum of squares over windows, count); within one window the sample nearest to the bin centre.
  std::map<long, std::pair<double, int>> bins;
  for (const auto& w : windows) {
    std::map<long, std::pair<double, double>> nearest;  // bin -> (|offset| from the centre, error)
    for (size_t i = 0; i < w.t_since_s.size(); ++i) {
      const long k = std::lround(w.t_since_s[i] / bin_s);
      const double off = std::abs(w.t_since_s[i] - static_cast<double>(k) * bin_s);
      if (off > 0.5 * bin_s + 1e-9 || k < 0) continue;
      auto it = nearest.find(k);
      if (it == nearest.end() || off < it->second.first) nearest[k] = {off, w.horizontal_m[i]};
    }
    for (const auto& [k, v] : nearest) {
      bins[k].first += v.second * v.second;
      bins[k].second += 1;
    }
  }
  RmsVsTime r;
  for (const auto& [k, v] : bins) {
    r.t_since_s.push_back(static_cast<double>(k) * bin_s);
    r.rms_m.push_back(std::sqrt(v.first / v.second));
    r.n_windows.push_back(v.second);
  }
  return r;
}

Cdf empirical_cdf(std::vector<double> values) {
  Cdf c;
  std::sort(values.begin(), values.end());
  const double n = static_cast<double>(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    c.value.push_back(values[i]);
    c.fraction.push_back(static_cast<double>(i + 1) / n);
  }
  return c;
}

}  // namespace pednav::eval
