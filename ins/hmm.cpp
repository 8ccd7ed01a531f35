// SPDX-License-Identifier: BSD-2-Clause
#include "ins/hmm.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

namespace pednav::ins {
namespace {

using Vec4 = Eigen::Vector4d;

// Row-normalize a matrix in place (rows with a zero sum are left as they are).
template <typename M>
void normalize_rows(M& m) {
  for (int i = 0; i < m.rows(); ++i) {
    const double s = m.row(i).sum();
    if (s > 0) m.row(i) /= s;
  }
}

bool valid_symbols(const std::vector<int>& symbols) {
  return std::all_of(symbols.begin(), symbols.end(), [](int s) { return s >= 0 && s < kHmmSymbols; });
}

// Seed 002 Table 1: observation probability [%] of grades 1..15 (rows) for states A, B, C, D (columns).
constexpr double kTable1Pct[kHmmSymbols][kHmmStates] = {
    {72.3, 12.3, 0, 0},    {9.23, 1.54, 0, 1.52}, {1.54, 0, 7.69, 1.52}, {0, 0, 43.08, 7.58},
    {0, 0, 30.77, 4.55},   {1.54, 0, 1.54, 0},    {0, 1.54, 0, 0},       {7.69, 0, 0, 24.2},
    {7.69, 0, 0, 60.6},    {0, 0, 1.54, 0},       {0, 3.08, 0, 0},       {0, 1.54, 1.54, 0},
    {0, 1.54, 1.54, 0},    {0, 73.85, 12.31, 0},  {0, 6.15, 0, 0}};

}  // namespace

char gait_state_letter(int state) { return state >= 0 && state < kHmmStates ? static_cast<char>('A' + state) : '-'; }

std::vector<std::string> HmmModel::problems() const {
  std::vector<std::string> p;
  constexpr double kSumTol = 1e-6;
  auto check = [&](const auto& m, const std::string& name) {
    for (int i = 0; i < m.rows(); ++i) {
      if (!m.row(i).allFinite() || (m.row(i).array() < 0).any()) {
        p.push_back(name + " row " + std::to_string(i + 1) + " has a negative or non-finite entry");
      } else if (std::abs(m.row(i).sum() - 1.0) > kSumTol) {
        p.push_back(name + " row " + std::to_string(i + 1) + " sums to " + std::to_string(m.row(i).sum()) +
                    ", not 1");
      }
    }
  };
  check(A, "A");
  check(B, "B");
  check(Eigen::RowVector4d(pi.transpose()), "pi");
  return p;
}

HmmModel seed002_initial_model(double floor) {
  HmmModel m;
  // seed 002 §3.2: A1 (trial and error), ideal cycle A -> B -> C -> D -> A with 0.85, 0.05 elsewhere.
  m.A << 0.05, 0.85, 0.05, 0.05,  //
      0.05, 0.05, 0.85, 0.05,     //
      0.05, 0.05, 0.05, 0.85,     //
      0.85, 0.05, 0.05, 0.05;
  for (int j = 0; j < kHmmStates; ++j) {
    for (int k = 0; k < kHmmSymbols; ++k) m.B(j, k) = std::max(kTable1Pct[k][j] / 100.0, floor);
  }
  normalize_rows(m.B);
  m.pi.setConstant(1.0 / kHmmStates);
  return m;
}

std::vector<std::string> HmmObservationOptions::problems() const {
  std::vector<std::string> p;
  if (axis < 0 || axis > 2) p.push_back("hmm gyro axis must be x, y or z");
  if (sign != 1.0 && sign != -1.0) p.push_back("hmm gyro axis sign must be +1 or -1");
  if (!(smooth_window_s >= 0)) p.push_back("hmm smoothing window must be >= 0 s");
  if (!(grade_width_radps > 0)) p.push_back("hmm grade width must be > 0");
  if (!(min_prominence_grades >= 0)) p.push_back("hmm extreme prominence must be >= 0 grades");
  return p;
}

std::vector<int> GaitObservations::symbols() const {
  std::vector<int> s(obs.size());
  for (std::size_t k = 0; k < obs.size(); ++k) s[k] = obs[k].symbol;
  return s;
}

int quantize_rate(double rate_radps, double grade_width_radps) {
  const double g = std::floor(rate_radps / grade_width_radps);
  return static_cast<int>(std::clamp(8.0 + g, 0.0, static_cast<double>(kHmmSymbols - 1)));
}

GaitObservations extract_gait_observations(const std::vector<ImuSample>& s, const HmmObservationOptions& o) {
  GaitObservations out;
  const std::size_t n = s.size();
  if (n == 0) return out;
  // a) signed rate about the axis across the foot.
  std::vector<double> raw(n);
  for (std::size_t k = 0; k < n; ++k) raw[k] = o.sign * s[k].omega_ib_b(o.axis);
  // b) centred moving average over smooth_window_s at the mean sample step (prefix sums).
  const double dt = n > 1 ? (s.back().t - s.front().t) / static_cast<double>(n - 1) : 1.0;
  const long h = std::lround(0.5 * o.smooth_window_s / std::max(dt, 1e-9));
  std::vector<double> prefix(n + 1, 0.0);
  for (std::size_t k = 0; k < n; ++k) prefix[k + 1] = prefix[k] + raw[k];
  out.rate_radps.resize(n);
  out.grade.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const long a = std::max(0L, static_cast<long>(k) - h);
    const long b = std::min(static_cast<long>(n) - 1, static_cast<long>(k) + h);
    out.rate_radps[k] = (prefix[b + 1] - prefix[a]) / static_cast<double>(b - a + 1);
    out.grade[k] = quantize_rate(out.rate_radps[k], o.grade_width_radps);
  }
  // c) extremes with hysteresis: a maximum (minimum) counts once the rate has fallen (risen) by more than
  //    `prominence` from it, so wiggles smaller than that, e.g. noise across a grade boundary, make no extremes.
  // d)+e) quantize each extreme; a run of consecutive extremes in the same grade is one observation.
  const auto& r = out.rate_radps;
  auto add = [&](std::size_t k) {
    if (!out.obs.empty() && out.obs.back().symbol == out.grade[k]) {
      out.obs.back().last = k;
      return;
    }
    out.obs.push_back({out.grade[k], k, k, r[k]});
  };
  add(0);
  const double prominence = o.min_prominence_grades * o.grade_width_radps;
  std::size_t imax = 0, imin = 0;
  int looking = 0;  // +1: for a maximum, -1: for a minimum, 0: either (start)
  for (std::size_t k = 1; k < n; ++k) {
    if (r[k] > r[imax]) imax = k;
    if (r[k] < r[imin]) imin = k;
    if (looking >= 0 && r[k] < r[imax] - prominence && imax > 0) {
      add(imax);
      looking = -1;
      imin = k;
    } else if (looking <= 0 && r[k] > r[imin] + prominence && imin > 0) {
      add(imin);
      looking = 1;
      imax = k;
    }
  }
  if (n > 1) add(n - 1);
  return out;
}

ForwardBackward forward_backward(const HmmModel& m, const std::vector<int>& o) {
  ForwardBackward fb;
  const std::size_t T = o.size();
  if (T == 0 || !valid_symbols(o)) {
    fb.log_likelihood = T == 0 ? 0.0 : -std::numeric_limits<double>::infinity();
    return fb;
  }
  fb.alpha_hat.resize(T);
  std::vector<double> c(T);  // c_t = 1 / Σ_i α_t(i) before scaling (Rabiner eq. 91)
  Vec4 a = m.pi.cwiseProduct(m.B.col(o[0]));
  for (std::size_t t = 0;; ++t) {
    const double sum = a.sum();
    if (!(sum > 0)) {
      fb.log_likelihood = -std::numeric_limits<double>::infinity();
      fb.alpha_hat.clear();
      return fb;
    }
    c[t] = 1.0 / sum;
    fb.alpha_hat[t] = a * c[t];
    fb.log_likelihood -= std::log(c[t]);
    if (t + 1 == T) break;
    a = (m.A.transpose() * fb.alpha_hat[t]).cwiseProduct(m.B.col(o[t + 1]));
  }
  // Backward with the same scale factors (Rabiner eq. 92-93): β̂_T = c_T, β̂_t = c_t A (b(o_{t+1}) ∘ β̂_{t+1}).
  fb.gamma.resize(T);
  Vec4 beta = Vec4::Constant(c[T - 1]);
  for (std::size_t t = T; t-- > 0;) {
    if (t + 1 < T) beta = c[t] * (m.A * m.B.col(o[t + 1]).cwiseProduct(beta));
    Vec4 g = fb.alpha_hat[t].cwiseProduct(beta);
    fb.gamma[t] = g / g.sum();
  }
  return fb;
}

BaumWelchResult baum_welch(const HmmModel& initial, const std::vector<std::vector<int>>& sequences,
                           const BaumWelchOptions& opt) {
  BaumWelchResult res;
  res.model = initial;
  for (const auto& s : sequences) {
    if (s.size() >= 2 && valid_symbols(s)) res.observations += static_cast<long>(s.size());
  }
  for (int it = 0;; ++it) {
    const HmmModel& m = res.model;
    // E-step: expected transition counts Σ_t ξ_t(i,j), state occupancies and symbol counts, summed over sequences.
    Eigen::Matrix4d xi_sum = Eigen::Matrix4d::Zero();
    Vec4 gamma_from = Vec4::Zero();  // Σ_{t<T} γ_t(i): denominator of a_ij (seed 002 eq. 3)
    Eigen::Matrix<double, kHmmStates, kHmmSymbols> emit = Eigen::Matrix<double, kHmmStates, kHmmSymbols>::Zero();
    Vec4 pi_sum = Vec4::Zero();
    int used = 0;
    double ll = 0.0;
    for (const auto& o : sequences) {
      if (o.size() < 2 || !valid_symbols(o)) continue;
      const ForwardBackward fb = forward_backward(m, o);
      ll += fb.log_likelihood;
      if (!std::isfinite(fb.log_likelihood)) continue;
      ++used;
      const std::size_t T = o.size();
      // ξ_t(i,j) ∝ α̂_t(i) a_ij b_j(o_{t+1}) β̂_{t+1}(j) = γ_{t+1}(j) α̂_t(i) a_ij / (Σ_i α̂_t(i) a_ij): this form
      // needs only α̂ and γ (Rabiner eq. 37 rewritten with γ_{t+1}(j) = α̂_{t+1}(j) β̂_{t+1}(j) / c_{t+1}).
      for (std::size_t t = 0; t + 1 < T; ++t) {
        const Vec4 pred = m.A.transpose() * fb.alpha_hat[t];  // Σ_i α̂_t(i) a_ij
        for (int j = 0; j < kHmmStates; ++j) {
          if (!(pred(j) > 0)) continue;
          xi_sum.col(j) += fb.alpha_hat[t].cwiseProduct(m.A.col(j)) * (fb.gamma[t + 1](j) / pred(j));
        }
        gamma_from += fb.gamma[t];
      }
      for (std::size_t t = 0; t < T; ++t) emit.col(o[t]) += fb.gamma[t];
      pi_sum += fb.gamma[0];
    }
    res.log_likelihood.push_back(ll);
    const std::size_t nll = res.log_likelihood.size();
    if (nll >= 2) {
      const double gain = (res.log_likelihood[nll - 1] - res.log_likelihood[nll - 2]) /
                          static_cast<double>(std::max(1L, res.observations));
      if (gain < opt.tolerance) {
        res.converged = true;
        break;
      }
    }
    if (it >= opt.max_iterations || used == 0) break;
    // M-step (seed 002 eq. 3, 4; b_j(k) = Σ_{t: o_t = k} γ_t(j) / Σ_t γ_t(j)). A state never visited keeps its rows.
    HmmModel next = m;
    for (int i = 0; i < kHmmStates; ++i) {
      if (gamma_from(i) > 0) next.A.row(i) = xi_sum.row(i) / xi_sum.row(i).sum();
      const double occ = emit.row(i).sum();
      if (occ > 0) next.B.row(i) = emit.row(i) / occ;
    }
    if (opt.update_pi && pi_sum.sum() > 0) next.pi = pi_sum / pi_sum.sum();
    res.model = next;
    res.iterations = it + 1;
  }
  return res;
}

std::vector<int> viterbi(const HmmModel& m, const std::vector<int>& o) {
  const std::size_t T = o.size();
  if (T == 0 || !valid_symbols(o)) return {};
  const Eigen::Matrix4d logA = m.A.array().log().matrix();
  const Eigen::Matrix<double, kHmmStates, kHmmSymbols> logB = m.B.array().log().matrix();
  std::vector<std::array<int, kHmmStates>> back(T);
  Vec4 delta = m.pi.array().log().matrix() + logB.col(o[0]);
  for (std::size_t t = 1; t < T; ++t) {
    Vec4 next;
    for (int j = 0; j < kHmmStates; ++j) {
      int best = 0;
      double v = -std::numeric_limits<double>::infinity();
      for (int i = 0; i < kHmmStates; ++i) {
        const double x = delta(i) + logA(i, j);
        if (x > v) {
          v = x;
          best = i;
        }
      }
      next(j) = v + logB(j, o[t]);
      back[t][static_cast<std::size_t>(j)] = best;
    }
    delta = next;
  }
  std::vector<int> q(T);
  Eigen::Index arg = 0;
  delta.maxCoeff(&arg);
  q[T - 1] = static_cast<int>(arg);
  for (std::size_t t = T - 1; t > 0; --t) q[t - 1] = back[t][static_cast<std::size_t>(q[t])];
  return q;
}

std::vector<int> forward_decode(const HmmModel& m, const std::vector<int>& o) {
  const ForwardBackward fb = forward_backward(m, o);
  std::vector<int> q(fb.alpha_hat.size());
  for (std::size_t t = 0; t < q.size(); ++t) {
    Eigen::Index arg = 0;
    fb.alpha_hat[t].maxCoeff(&arg);
    q[t] = static_cast<int>(arg);
  }
  return q;
}

HmmModel floored(const HmmModel& model, double floor) {
  HmmModel m = model;
  m.A = m.A.cwiseMax(floor);
  m.B = m.B.cwiseMax(floor);
  m.pi = m.pi.cwiseMax(floor);
  normalize_rows(m.A);
  normalize_rows(m.B);
  m.pi /= m.pi.sum();
  return m;
}

HmmDraw draw_hmm_sequence(const HmmModel& m, int length, std::uint64_t seed) {
  HmmDraw d;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto pick = [&](const auto& probs) {
    const double x = u(rng);
    double acc = 0.0;
    for (int k = 0; k < static_cast<int>(probs.size()); ++k) {
      acc += probs(k);
      if (x < acc) return k;
    }
    return static_cast<int>(probs.size()) - 1;
  };
  int q = pick(m.pi);
  for (int t = 0; t < length; ++t) {
    d.states.push_back(q);
    d.symbols.push_back(pick(m.B.row(q)));
    q = pick(m.A.row(q));
  }
  return d;
}

std::vector<int> states_per_sample(const GaitObservations& g, const std::vector<int>& q,
                                   const std::array<bool, kHmmSymbols>& stance_grades) {
  const std::size_t n = g.rate_radps.size(), N = g.obs.size();
  std::vector<int> out(n, -1);
  if (n == 0 || N == 0 || q.size() != N) return out;
  // Dwell [lo_k, hi_k] of observation k: its extremes, widened while the grade stays its symbol (stance: while
  // the grade is its symbol or one of stance_grades), never beyond the neighbouring observations' extremes.
  std::vector<std::size_t> lo(N), hi(N);
  for (std::size_t k = 0; k < N; ++k) {
    const auto& ob = g.obs[k];
    const std::size_t left_bound = k > 0 ? g.obs[k - 1].last + 1 : 0;
    const std::size_t right_bound = k + 1 < N ? g.obs[k + 1].first - 1 : n - 1;
    auto in_dwell = [&](std::size_t i) {
      return g.grade[i] == ob.symbol || (q[k] == kStance && stance_grades[static_cast<std::size_t>(g.grade[i])]);
    };
    lo[k] = ob.first;
    hi[k] = ob.last;
    while (lo[k] > left_bound && in_dwell(lo[k] - 1)) --lo[k];
    while (hi[k] < right_bound && in_dwell(hi[k] + 1)) ++hi[k];
  }
  for (std::size_t k = 0; k < N; ++k) {
    // Transit to the next observation's dwell: the next state, except into stance (keep this state).
    if (k + 1 < N) {
      const int transit = q[k + 1] == kStance ? q[k] : q[k + 1];
      for (std::size_t i = hi[k] + 1; i < std::max(lo[k + 1], hi[k] + 1); ++i) out[i] = transit;
    }
  }
  for (std::size_t i = 0; i < lo[0]; ++i) out[i] = q[0];
  // Dwells last, stance dwells after the others: a widened stance dwell wins where it overlaps a neighbour's.
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t k = 0; k < N; ++k) {
      if ((q[k] == kStance) != (pass == 1)) continue;
      for (std::size_t i = lo[k]; i <= hi[k]; ++i) out[i] = q[k];
    }
  }
  return out;
}

std::array<bool, kHmmSymbols> stance_grades(const HmmModel& model, double min_probability) {
  std::array<bool, kHmmSymbols> g{};
  for (int k = 0; k < kHmmSymbols; ++k) g[static_cast<std::size_t>(k)] = model.B(kStance, k) >= min_probability;
  g[7] = g[8] = true;  // grades 8 and 9 meet at zero rate: noise at rest alternates between them
  return g;
}

}  // namespace pednav::ins
