// SPDX-License-Identifier: BSD-2-Clause
// GLONASS inter-frequency phase bias search (fusion/glonass_ifb.hpp, docs/carrier.md §3.1).
#include "fusion/glonass_ifb.hpp"

#include <algorithm>
#include <cmath>

#include "gnss/types.hpp"

namespace pednav::fusion {
namespace {

constexpr double kSpeedOfLight_mps = 299792458.0;
constexpr double kGlonassL1Base_hz = 1602.0e6;
constexpr double kGlonassL1Step_hz = 0.5625e6;
constexpr double kLambda0_m = kSpeedOfLight_mps / kGlonassL1Base_hz;  // the period of β (eq. 3.10)

}  // namespace

int glonass_channel(double wavelength_m) {
  if (!(wavelength_m > 0.0)) return 0;
  const double k = (kSpeedOfLight_mps / wavelength_m - kGlonassL1Base_hz) / kGlonassL1Step_hz;
  const double r = std::round(k);
  // Channels −7 … +6 (ICD); a wavelength off the channel grid is not GLONASS L1.
  if (std::abs(k - r) > 0.01 || r < -7.0 || r > 6.0) return 0;
  return static_cast<int>(r);
}

Eigen::VectorXd glonass_ifb_offsets(int n_state, const std::vector<AmbiguityCandidate>& c, double beta_m) {
  Eigen::VectorXd d = Eigen::VectorXd::Zero(n_state);
  for (const auto& a : c) {
    if (a.sat.system != gnss::System::kGlonass || !(a.wavelength_m > 0.0) || a.state < 0 || a.state >= n_state) continue;
    d(a.state) = beta_m * glonass_channel(a.wavelength_m) / a.wavelength_m;
  }
  return d;
}

bool GlonassIfbSearch::search(const Eigen::VectorXd& x, const Eigen::MatrixXd& P,
                              const std::vector<AmbiguityCandidate>& c, const AmbiguityOptions& ar) {
  if (beta_m_) return false;
  std::vector<AmbiguityCandidate> cands = c;
  int n_glo = 0;
  for (auto& a : cands) {
    if (a.sat.system != gnss::System::kGlonass) continue;
    a.integer = a.wavelength_m > 0.0;
    n_glo += a.integer && a.elevation_rad >= ar.ar_elevation_mask_rad && a.lock_epochs >= ar.min_lock_epochs;
  }
  if (n_glo < o_.min_glonass) return false;
  ++searches_;
  // One period of β, centred on 0: indices −half … half−1.
  const int half = static_cast<int>(std::floor(0.5 * kLambda0_m / o_.step_m));
  const int n_grid = 2 * half;
  if (votes_.size() != static_cast<size_t>(n_grid)) votes_.assign(n_grid, 0);
  AmbiguityOptions full = ar;
  full.partial = false;  // a subset without GLONASS would not depend on β
  int best = -1;
  double best_ratio = 0.0;
  bool best_fixed = false;
  for (int j = -half; j < half; ++j) {
    const double beta = j * o_.step_m;
    const AmbiguityFix f = resolve_ambiguities(x - glonass_ifb_offsets(static_cast<int>(x.size()), cands, beta), P,
                                               cands, full);
    if (f.ratio > best_ratio) best_ratio = f.ratio, best = j, best_fixed = f.fixed;
  }
  if (best < -half || !best_fixed) return false;
  ++votes_cast_;
  ++votes_[best + half];
  // Eq. 3.11: the window of three grid cells (circular: β is periodic) with the most votes against every window that
  // does not overlap it.
  auto at = [&](int i) { return votes_[((i % n_grid) + n_grid) % n_grid]; };
  int lead = 0, lead_votes = -1;
  for (int i = 0; i < n_grid; ++i) {
    const int v = at(i - 1) + at(i) + at(i + 1);
    if (v > lead_votes) lead_votes = v, lead = i;
  }
  int other = 0;
  for (int i = 0; i < n_grid; ++i) {
    const int d = std::min(std::abs(i - lead), n_grid - std::abs(i - lead));
    if (d >= 3) other = std::max(other, at(i - 1) + at(i) + at(i + 1));
  }
  if (lead_votes < o_.votes || lead_votes < o_.dominance * other) return false;
  double sum = 0.0;
  for (int di = -1; di <= 1; ++di) sum += at(lead + di) * ((lead - half) + di) * o_.step_m;
  beta_m_ = sum / lead_votes;
  return true;
}

}  // namespace pednav::fusion
