// SPDX-License-Identifier: BSD-2-Clause
#include "ins/zupt_detector.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

namespace pednav::ins {
namespace {

constexpr double kGravityNominal_mps2 = 9.80665;  // g of SHOE (Skog et al. 2010) and MAG

// Half window in samples for a window of `window_s` at the median sample step.
int half_window(const std::vector<ImuSample>& s, double window_s) {
  if (s.size() < 2) return 0;
  const double dt = (s.back().t - s.front().t) / static_cast<double>(s.size() - 1);
  return std::max(1, static_cast<int>(std::lround(0.5 * window_s / std::max(dt, 1e-6))));
}

void drop_short_runs(std::vector<ZuptDecision>& d, const std::vector<ImuSample>& s, double min_s) {
  size_t i = 0;
  while (i < d.size()) {
    if (!d[i].stance) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < d.size() && d[j + 1].stance) ++j;
    if (s[j].t - s[i].t < min_s) {
      for (size_t k = i; k <= j; ++k) d[k].stance = false;
    }
    i = j + 1;
  }
}

}  // namespace

// Seed 004's Δt applied to the HMM's stance: the foot cannot push off and stand again without a swing. Such a run is
// a D decoded on the in-air zero crossing of the rate between push-off and swing (LORD #34 at 7.01 s and 7.91 s, #38
// at 17.52 s: each 0.05 s long, 0.22-0.26 s after the true stance ended; docs/zupt.md §3).
void drop_stances_right_after_push_off(std::vector<ZuptDecision>& d, const std::vector<ImuSample>& s, double min_s) {
  if (min_s <= 0.0) return;
  std::ptrdiff_t last_end = -1;  // sample index of the last kept stance run's end
  bool pushed_off = false;       // a push-off sample since last_end
  for (std::size_t i = 0; i < d.size();) {
    if (!d[i].stance) {
      pushed_off = pushed_off || d[i].gait_state == kPushOff;
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j + 1 < d.size() && d[j + 1].stance) ++j;
    if (last_end >= 0 && pushed_off && s[i].t - s[static_cast<std::size_t>(last_end)].t < min_s) {
      for (std::size_t k = i; k <= j; ++k) d[k].stance = false;
    } else {
      last_end = static_cast<std::ptrdiff_t>(j);
      pushed_off = false;
    }
    i = j + 1;
  }
}

std::vector<std::string> ZuptDetectorOptions::problems() const {
  std::vector<std::string> p;
  if (detector != "mv" && detector != "shoe" && detector != "are" && detector != "mag" && detector != "hmm" &&
      detector != "labels") {
    p.push_back("zupt.detector '" + detector + "' is not mv, shoe, are, mag, hmm or labels");
  }
  if (are_threshold <= 0) p.push_back("zupt.are_threshold must be > 0");
  if (mag_threshold <= 0) p.push_back("zupt.mag_threshold must be > 0");
  if (detector == "hmm") {
    for (const auto& q : hmm_observations.problems()) p.push_back("zupt." + q);
    if (hmm_model) {
      for (const auto& q : hmm_model->problems()) p.push_back("zupt.hmm_model: " + q);
    }
    if (hmm_decoder != "viterbi" && hmm_decoder != "forward") {
      p.push_back("zupt.hmm_decoder '" + hmm_decoder + "' is not viterbi or forward");
    }
    if (hmm_max_iterations < 0) p.push_back("zupt.hmm_max_iterations must be >= 0");
    if (!(hmm_decode_floor >= 0 && hmm_decode_floor < 0.01)) p.push_back("zupt.hmm_decode_floor must be in [0, 0.01)");
    if (!(hmm_min_swing_s >= 0)) p.push_back("zupt.hmm_min_swing_s must be >= 0");
  }
  if (mv_window_s <= 0) p.push_back("zupt.mv_window_s must be > 0");
  if (mv_threshold_mps2 <= 0) p.push_back("zupt.mv_threshold_mps2 must be > 0");
  if (shoe_window_s <= 0) p.push_back("zupt.shoe_window_s must be > 0");
  if (shoe_threshold <= 0) p.push_back("zupt.shoe_threshold must be > 0");
  if (shoe_sigma_accel_mps2 <= 0 || shoe_sigma_gyro_radps <= 0) p.push_back("zupt.shoe sigmas must be > 0");
  if (min_time_since_step_s < 0) p.push_back("zupt.min_time_since_step_s must be >= 0");
  return p;
}

// docs/zupt.md §3: keep the contiguous core of each stance run where the SHOE statistic is below
// max(γ, factor · its minimum in the run), widened to min_stance_s, and the run's other samples with T < γ.
void refine_hmm_stances(std::vector<ZuptDecision>& d, const std::vector<ImuSample>& s, const std::vector<double>& t,
                        const ZuptDetectorOptions& o) {
  auto next_stance_start = [&](std::size_t j) {  // first stance sample after the run ending at j (or the end)
    std::size_t k = j + 1;
    while (k < s.size() && !d[k].stance) ++k;
    return k;
  };
  std::size_t prev_end = 0;  // one past the previous (refined) stance run
  for (std::size_t i = 0; i < s.size();) {
    if (!d[i].stance) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j + 1 < s.size() && d[j + 1].stance) ++j;
    std::size_t m = i;
    for (std::size_t k = i; k <= j; ++k) {
      if (t[k] < t[m]) m = k;
    }
    const double thr = std::max(o.shoe_threshold, o.hmm_refine_factor * t[m]);
    std::size_t a = m, b = m;
    while (a > i && t[a - 1] < thr) --a;
    while (b < j && t[b + 1] < thr) ++b;
    // Refinement never removes a step: the core is widened (towards the smaller T) to min_stance_s — beyond the
    // decoded D run when that is shorter and is a whole step of its own: framed by heel strike and push-off, with
    // a swing since the previous stance (a fast step whose stance is one observation) — but never into the
    // neighbouring stance runs.
    bool swing_before = false;
    for (std::size_t k = prev_end; k < i && !swing_before; ++k) swing_before = d[k].gait_state == kSwing;
    const bool full_cycle = swing_before && i > 0 && j + 1 < s.size() &&
                            d[i - 1].gait_state == kHeelStrike && d[j + 1].gait_state == kPushOff;
    const std::size_t lo = full_cycle ? prev_end : i, hi = full_cycle ? next_stance_start(j) : j + 1;
    while (s[b].t - s[a].t < o.min_stance_s && (a > lo || b + 1 < hi)) {
      if (b + 1 >= hi || (a > lo && t[a - 1] < t[b + 1])) {
        --a;
      } else {
        ++b;
      }
    }
    // Outside the core, the decoded stance keeps the samples that pass SHOE's own test (T < γ): the HMM says which
    // phase the foot is in, SHOE which of its samples are still. A foot that rocks on its heel and toe has two quiet
    // parts in one stance; the core keeps one of them.
    for (std::size_t k = std::min(a, i); k <= std::max(b, j); ++k)
      d[k].stance = (k >= a && k <= b) || (k >= i && k <= j && t[k] < o.shoe_threshold);
    prev_end = b + 1;
    i = std::max(b, j) + 1;
  }
}

HmmDetection detect_gait_hmm(const std::vector<ImuSample>& s, const ZuptDetectorOptions& o) {
  HmmDetection h;
  h.decisions.resize(s.size());
  const HmmModel initial = o.hmm_model ? *o.hmm_model : seed002_initial_model();
  auto extract = [&](double sign) {
    HmmObservationOptions x = o.hmm_observations;
    x.sign = sign;
    return extract_gait_observations(s, x);
  };
  // Axis sign: the configured one, or (hmm_auto_sign) the one that makes push-off negative as in seed 002
  // (Fig. 2e, Table 1: push-off emits the lowest grades). Push-off is the first large excursion after a rest:
  // after every run of >= kRestForSign_s in the two grades at zero rate, the first sample at >= kExcursionGrades
  // grades beyond them votes with its sign; a majority of positive votes flips the sign, a tie keeps the
  // configured one.
  h.sign = o.hmm_observations.sign;
  h.observations = extract(h.sign);
  if (o.hmm_auto_sign) {
    constexpr double kRestForSign_s = 0.1;
    constexpr int kExcursionGrades = 3;
    // Rest: the two grades that meet at zero rate (8 = [-w, 0), 9 = [0, w); 0-based 7 and 8).
    auto rest = [](int grade) { return grade == 7 || grade == 8; };
    const auto& g = h.observations.grade;
    int votes = 0;  // positive first excursions minus negative ones
    for (std::size_t k = 0; k < g.size();) {
      if (!rest(g[k])) {
        ++k;
        continue;
      }
      std::size_t j = k;
      while (j + 1 < g.size() && rest(g[j + 1])) ++j;
      if (s[j].t - s[k].t >= kRestForSign_s) {
        std::size_t m = j + 1;
        while (m < g.size() && g[m] > 7 - kExcursionGrades && g[m] < 8 + kExcursionGrades) ++m;
        if (m < g.size()) votes += g[m] > 8 ? 1 : -1;
      }
      k = j + 1;
    }
    if (votes > 0) {
      h.sign = -h.sign;
      h.observations = extract(h.sign);
    }
  }
  h.model = initial;
  const std::vector<int> symbols = h.observations.symbols();
  if (o.hmm_train_on_log && symbols.size() >= 2) {
    BaumWelchOptions bw;
    bw.max_iterations = o.hmm_max_iterations;
    h.training = baum_welch(initial, {symbols}, bw);
    h.model = h.training.model;
  }
  const HmmModel decode_model = floored(h.model, o.hmm_decode_floor);
  h.obs_states = o.hmm_decoder == "forward" ? forward_decode(decode_model, symbols) : viterbi(decode_model, symbols);
  const std::array<bool, kHmmSymbols> still = stance_grades(h.model, o.hmm_stance_grade_probability);
  const std::vector<int> per_sample = states_per_sample(h.observations, h.obs_states, still);
  for (std::size_t k = 0; k < s.size(); ++k) {
    h.decisions[k].statistic = h.observations.rate_radps[k];
    h.decisions[k].gait_state = per_sample[k];
    // Stance = state D AND a stance grade: a D decoded on an extreme far from zero rate (e.g. grade 13 at the
    // first, half step of the x-io long walk, b_D = 0.026) would otherwise put its whole swing dwell into stance.
    h.decisions[k].stance = per_sample[k] == kStance && still[static_cast<std::size_t>(h.observations.grade[k])];
  }
  // A long rest (smoothed rate within one grade of zero for >= hmm_rest_s) is stance whatever was decoded: the
  // trained cycle has no D -> D transition, and a rest is one merged observation (e.g. the final 14 s of the x-io
  // long walk, decoded as push-off after a short last step).
  if (o.hmm_rest_s > 0) {
    const auto& g = h.observations.grade;
    for (std::size_t k = 0; k < g.size();) {
      if (g[k] != 7 && g[k] != 8) {
        ++k;
        continue;
      }
      std::size_t j = k;
      while (j + 1 < g.size() && (g[j + 1] == 7 || g[j + 1] == 8)) ++j;
      if (s[j].t - s[k].t >= o.hmm_rest_s) {
        for (std::size_t i = k; i <= j; ++i) h.decisions[i].stance = true;
      }
      k = j + 1;
    }
  }
  // Stance shortening with a gait-speed adaptive threshold (refine_hmm_stances).
  if (o.hmm_refine_factor > 0) refine_hmm_stances(h.decisions, s, shoe_statistic(s, o), o);
  drop_short_runs(h.decisions, s, o.min_stance_s);
  drop_stances_right_after_push_off(h.decisions, s, o.hmm_min_swing_s);
  return h;
}

std::vector<double> shoe_statistic(const std::vector<ImuSample>& s, const ZuptDetectorOptions& o) {
  const int n = static_cast<int>(s.size());
  std::vector<double> out(s.size(), 0.0);
  const int h = half_window(s, o.shoe_window_s);
  const double ia = 1.0 / (o.shoe_sigma_accel_mps2 * o.shoe_sigma_accel_mps2);
  const double ig = 1.0 / (o.shoe_sigma_gyro_radps * o.shoe_sigma_gyro_radps);
  for (int k = 0; k < n; ++k) {
    const int a = std::max(0, k - h), b = std::min(n - 1, k + h);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int j = a; j <= b; ++j) mean += s[j].f_ib_b;
    mean /= static_cast<double>(b - a + 1);
    const Eigen::Vector3d g_dir =
        mean.norm() > 0 ? Eigen::Vector3d(mean.normalized() * kGravityNominal_mps2) : Eigen::Vector3d::Zero();
    double t = 0.0;
    for (int j = a; j <= b; ++j) t += ia * (s[j].f_ib_b - g_dir).squaredNorm() + ig * s[j].omega_ib_b.squaredNorm();
    out[k] = t / static_cast<double>(b - a + 1);
  }
  return out;
}

std::vector<std::pair<std::size_t, std::size_t>> stance_phases(const std::vector<ZuptDecision>& d) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  for (std::size_t i = 0; i < d.size();) {
    if (!d[i].stance) {
      ++i;
      continue;
    }
    std::size_t j = i;
    for (;;) {
      while (j + 1 < d.size() && d[j + 1].stance) ++j;
      // Merge the next run when every sample in between was decoded stance (HMM): the same footfall.
      std::size_t k = j + 1;
      while (k < d.size() && !d[k].stance && d[k].gait_state == kStance) ++k;
      if (k == j + 1 || k >= d.size() || !d[k].stance) break;
      j = k;
    }
    out.emplace_back(i, j);
    i = j + 1;
  }
  return out;
}

namespace {
// f(i, j) for every run of stance decisions d[i..j] (inclusive) among the first n.
template <typename F>
void for_each_stance_run(const std::vector<ZuptDecision>& d, std::size_t n, F&& f) {
  for (std::size_t i = 0; i < n;) {
    if (!d[i].stance) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j + 1 < n && d[j + 1].stance) ++j;
    f(i, j);
    i = j + 1;
  }
}
}  // namespace

std::vector<bool> zupt_update_samples(const std::vector<ZuptDecision>& d, const std::vector<ImuSample>& s,
                                      double edge_s, double min_core_s) {
  std::vector<bool> ok(d.size(), false);
  for_each_stance_run(d, std::min(d.size(), s.size()), [&](std::size_t i, std::size_t j) {
    // Times from the run's first sample: the run without its edges, or else its central min_core_s.
    const double len = s[j].t - s[i].t;
    double lo = edge_s, hi = len - edge_s;
    if (hi - lo < min_core_s) {
      const double half = 0.5 * std::min(min_core_s, len);
      lo = 0.5 * len - half;
      hi = 0.5 * len + half;
    }
    bool any = false;
    for (std::size_t k = i; k <= j; ++k) {
      const double tk = s[k].t - s[i].t;
      ok[k] = tk >= lo - 1e-9 && tk <= hi + 1e-9;
      any = any || ok[k];
    }
    if (!any) ok[i + (j - i) / 2] = true;
  });
  return ok;
}

std::vector<bool> zupt_forced_interval_ends(const std::vector<ZuptDecision>& d, const std::vector<bool>& ok,
                                            const std::vector<ImuSample>& s, int64_t period_ns) {
  const std::size_t n = std::min({d.size(), ok.size(), s.size()});
  std::vector<bool> cut(d.size(), false);
  if (period_ns <= 0) return cut;
  // Grid points in (a, b]: floor(b / P) − floor(a / P) (times in ns, P > 0; floor division for negative times too).
  auto floor_div = [period_ns](int64_t t) { return t >= 0 ? t / period_ns : -((-t + period_ns - 1) / period_ns); };
  auto completes = [&](std::size_t k) { return k > 0 && floor_div(s[k].t.ns()) > floor_div(s[k - 1].t.ns()); };
  for_each_stance_run(d, n, [&](std::size_t i, std::size_t j) {
    bool updated = false;
    std::size_t first_ok = n, last_ok = n;
    for (std::size_t k = i; k <= j; ++k) {
      if (!ok[k]) continue;
      if (first_ok == n) first_ok = k;
      last_ok = k;
      updated = updated || completes(k);
    }
    if (!updated && first_ok < n) cut[first_ok + (last_ok - first_ok) / 2] = true;
  });
  return cut;
}

std::string stance_label_problem(const ZuptDetectorOptions& o, const std::vector<uint8_t>* labels, size_t n_samples) {
  if (o.detector != "labels") return {};
  if (!labels || labels->empty())
    return "zupt.detector labels: the IMU log has no stance labels (imu.format: stance: {column: N})";
  if (labels->size() != n_samples)
    return "zupt.detector labels: " + std::to_string(labels->size()) + " stance labels for " +
           std::to_string(n_samples) + " IMU samples";
  return {};
}

std::vector<ZuptDecision> detect_stance(const std::vector<ImuSample>& s, const ZuptDetectorOptions& o,
                                        const std::vector<uint8_t>* labels) {
  const int n = static_cast<int>(s.size());
  std::vector<ZuptDecision> d(n);
  if (n == 0) return d;
  if (o.detector == "labels") {
    for (int k = 0; k < n; ++k) {
      d[k].stance = labels && static_cast<size_t>(k) < labels->size() && (*labels)[static_cast<size_t>(k)] != 0;
      d[k].statistic = d[k].stance ? 1.0 : 0.0;
    }
    return d;
  }
  if (o.detector == "hmm") return detect_gait_hmm(s, o).decisions;
  if (o.detector == "are" || o.detector == "mag") {
    // Skog et al. 2010 eq. 8 (ARE) and 9 (MAG), window W centred on the sample.
    const int h = half_window(s, o.shoe_window_s);
    const double ia = 1.0 / (o.shoe_sigma_accel_mps2 * o.shoe_sigma_accel_mps2);
    const double ig = 1.0 / (o.shoe_sigma_gyro_radps * o.shoe_sigma_gyro_radps);
    const bool are = o.detector == "are";
    for (int k = 0; k < n; ++k) {
      const int a = std::max(0, k - h), b = std::min(n - 1, k + h);
      double t = 0.0;
      for (int j = a; j <= b; ++j) {
        if (are) {
          t += ig * s[j].omega_ib_b.squaredNorm();
        } else {
          const double e = s[j].f_ib_b.norm() - kGravityNominal_mps2;
          t += ia * e * e;
        }
      }
      d[k].statistic = t / static_cast<double>(b - a + 1);
      d[k].stance = d[k].statistic < (are ? o.are_threshold : o.mag_threshold);
    }
  } else if (o.detector == "shoe") {
    const std::vector<double> t = shoe_statistic(s, o);
    // Gait-adaptive threshold: a fast gait's stance never gets below γ (LORD #35: min T per stance up to 219), so the
    // threshold follows the local minimum of T (the stance of the current step) when that is above γ / factor.
    const int hw = o.shoe_adaptive_factor > 0 ? half_window(s, o.shoe_adaptive_window_s) : 0;
    // Only where the window also holds a swing (peak |ω| >= shoe_adaptive_min_peak_radps): slow motion without
    // swings keeps γ.
    const bool swing_condition = hw > 0 && o.shoe_adaptive_min_peak_radps > 0;
    std::deque<int> mins;   // indices of increasing T over the sliding window (monotone queue)
    std::deque<int> peaks;  // indices of decreasing |ω| over the same window (swing condition only)
    std::vector<double> rate(swing_condition ? n : 0);
    for (int k = 0; k < static_cast<int>(rate.size()); ++k) rate[k] = s[k].omega_ib_b.norm();
    int next = 0;
    for (int k = 0; k < n; ++k) {
      d[k].statistic = t[k];
      double thr = o.shoe_threshold;
      if (hw > 0) {
        for (; next < n && next <= k + hw; ++next) {
          while (!mins.empty() && t[mins.back()] >= t[next]) mins.pop_back();
          mins.push_back(next);
          if (!swing_condition) continue;
          while (!peaks.empty() && rate[peaks.back()] <= rate[next]) peaks.pop_back();
          peaks.push_back(next);
        }
        while (mins.front() < k - hw) mins.pop_front();
        while (swing_condition && peaks.front() < k - hw) peaks.pop_front();
        const double m = t[mins.front()];
        const bool swing_near = !swing_condition || rate[peaks.front()] >= o.shoe_adaptive_min_peak_radps;
        if (m < o.shoe_adaptive_max && swing_near) thr = std::max(thr, o.shoe_adaptive_factor * m);
      }
      d[k].stance = t[k] < thr;
    }
  } else {
    // seed 004 eq. 1: sigma_{k} = std of |f| over the window; stance if sigma < threshold and t_k - t_s > Δt,
    // t_s = start of the current step (the last sample that was moving after a stance).
    const int h = half_window(s, o.mv_window_s);
    std::vector<double> mag(n);
    for (int k = 0; k < n; ++k) mag[k] = s[k].f_ib_b.norm();
    bool moving = true;
    GpsTime step_start = s.front().t.plus_s(-1e3);  // the log may start still
    for (int k = 0; k < n; ++k) {
      const int a = std::max(0, k - h), b = std::min(n - 1, k + h);
      double m = 0.0, m2 = 0.0;
      for (int j = a; j <= b; ++j) {
        m += mag[j];
        m2 += mag[j] * mag[j];
      }
      const double cnt = static_cast<double>(b - a + 1);
      const double var = std::max(0.0, m2 / cnt - (m / cnt) * (m / cnt));
      d[k].statistic = std::sqrt(var);
      const bool quiet = d[k].statistic < o.mv_threshold_mps2 &&
                         (o.mv_gyro_threshold_radps <= 0 || s[k].omega_ib_b.norm() < o.mv_gyro_threshold_radps);
      if (!quiet) {
        if (!moving) step_start = s[k].t;  // a new step begins
        moving = true;
        d[k].stance = false;
      } else {
        d[k].stance = (s[k].t - step_start) > o.min_time_since_step_s;
        if (d[k].stance) moving = false;
      }
    }
  }
  drop_short_runs(d, s, o.min_stance_s);
  return d;
}

}  // namespace pednav::ins
