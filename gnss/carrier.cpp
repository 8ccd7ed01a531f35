// SPDX-License-Identifier: BSD-2-Clause
// Carrier-phase model, slip screening and double differences: see gnss/carrier.hpp and docs/carrier.md.
#include "gnss/carrier.hpp"

#include "gnss/base_phase.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace pednav::gnss {

bool integer_ambiguity_system(System s) { return s != System::kGlonass && s != System::kSbas && s != System::kIrnss; }

MeasurementRow sd_carrier_phase(SatId sat, const SignalAtReceiver& rover, const SignalAtReceiver& base,
                                const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& p_eb_e, double clock_rb_m) {
  // Eq. 1.1: the geometry, satellite clocks and differential clock are those of the SD code (eq. 1.2: the
  // ionosphere enters with the opposite sign, and cancels with the troposphere on short baselines in both).
  return sd_pseudorange(sat, rover, base, p_ea_e, p_eb_e, clock_rb_m);
}

MeasurementRow td_carrier_phase(SatId sat, const SignalAtReceiver& now, const SignalAtReceiver& prev,
                                const Eigen::Vector3d& p_now_e, const Eigen::Vector3d& p_prev_e, double clock_change_m) {
  // Eq. 9.1: each epoch's phase range against the undifferenced code model without atmosphere (its change over one
  // epoch interval is left out, eq. 9.2) and with the receiver clock's change as the one clock term.
  const MeasurementRow k = ud_pseudorange(sat, now, p_now_e, 0.0, 0.0, 0.0);
  const MeasurementRow j = ud_pseudorange(sat, prev, p_prev_e, 0.0, 0.0, 0.0);
  MeasurementRow out;
  out.sat = sat;
  out.residual = k.residual - j.residual - clock_change_m;
  out.J_p = k.J_p;
  out.J_v = -j.J_p;
  out.J_clock = 1.0;
  return out;
}

double carrier_sigma_m(const WeightModel& model, double carrier_sigma_zenith_m, double cn0_dbhz, double elevation_rad) {
  WeightModel m = model;
  m.code_sigma_zenith_m = carrier_sigma_zenith_m;
  m.code_squaring_loss = 0.0;  // a DLL property (eq. W2), not the PLL's
  return measurement_sigma(m, cn0_dbhz, elevation_rad, false);
}

const char* slip_reason_name(SlipReason r) {
  switch (r) {
    case SlipReason::kLossOfLock: return "loss_of_lock";
    case SlipReason::kHalfCycle: return "half_cycle";
    case SlipReason::kDoppler: return "doppler";
    case SlipReason::kGeometry: return "geometry";
    case SlipReason::kGap: return "gap";
    case SlipReason::kWrongFix: return "wrong_fix";
    case SlipReason::kCount: break;
  }
  return "?";
}

void PhaseSlipScreen::forget(SatId sat) {
  std::erase_if(history_, [&](const auto& h) { return h.first == sat; });
}

std::vector<std::optional<SlipReason>> PhaseSlipScreen::screen(const ObsEpoch& epoch) {
  const size_t n = epoch.sats.size();
  std::vector<std::optional<SlipReason>> out(n);
  std::vector<long> prev(n, -1);  // index into history_ (indices: history_ grows below)
  std::vector<double> d(n, kNaN);  // ΔΦ + ½(D_prev + D_now) Δt [cycles], eq. 2.1
  diffs_.clear();
  for (size_t i = 0; i < n; ++i) {
    const SatObs& s = epoch.sats[i];
    if (!std::isfinite(s.carrier_cycles)) continue;
    auto it = std::find_if(history_.begin(), history_.end(), [&](const auto& h) { return h.first == s.sat; });
    if (it == history_.end() || !std::isfinite(it->second.phase_cycles)) continue;  // a new arc: nothing to compare
    PhaseHistory& h = it->second;
    prev[i] = it - history_.begin();
    const double dt = epoch.time - h.t;
    if (dt <= 0.0) continue;
    if (dt > o_.max_gap_s) { out[i] = SlipReason::kGap; continue; }
    if (s.lli & kLliSlip) { out[i] = SlipReason::kLossOfLock; continue; }
    if (((s.lli & kLliHalfCycle) != 0) != h.half_cycle) { out[i] = SlipReason::kHalfCycle; continue; }
    if (std::isfinite(s.doppler_hz) && std::isfinite(h.doppler_hz)) {
      d[i] = (s.carrier_cycles - h.phase_cycles) + 0.5 * (s.doppler_hz + h.doppler_hz) * dt;
      diffs_.push_back(d[i]);
    }
  }
  // A receiver clock step moves every phase by the same range (and the Doppler not): remove the epoch's median.
  double common = 0.0;
  if (diffs_.size() >= 3) {
    std::nth_element(diffs_.begin(), diffs_.begin() + diffs_.size() / 2, diffs_.end());
    common = diffs_[diffs_.size() / 2];
  }
  for (size_t i = 0; i < n; ++i) {
    if (out[i] || !std::isfinite(d[i])) continue;
    const double dt = epoch.time - history_[prev[i]].second.t;
    if (std::abs(d[i] - common) > o_.threshold_cycles + o_.threshold_per_s_cycles * dt) out[i] = SlipReason::kDoppler;
  }
  // Keep the history: every satellite with phase now; those without phase keep their last phase (a gap).
  for (size_t i = 0; i < n; ++i) {
    const SatObs& s = epoch.sats[i];
    if (!std::isfinite(s.carrier_cycles)) continue;
    PhaseHistory h{epoch.time, s.carrier_cycles, s.doppler_hz, (s.lli & kLliHalfCycle) != 0};
    if (prev[i] >= 0) {
      history_[prev[i]].second = h;
    } else {
      auto it = std::find_if(history_.begin(), history_.end(), [&](const auto& x) { return x.first == s.sat; });
      if (it != history_.end()) it->second = h;
      else history_.emplace_back(s.sat, h);
    }
  }
  return out;
}

Eigen::MatrixXd double_difference_operator(const std::vector<int>& members, int ref_pos, int n) {
  const int m = static_cast<int>(members.size());
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(std::max(0, m - 1), n);
  int row = 0;
  for (int k = 0; k < m; ++k) {
    if (k == ref_pos) continue;
    D(row, members[k]) = 1.0;
    D(row, members[ref_pos]) = -1.0;
    ++row;
  }
  return D;
}

BasePhaseArcs screen_base_phase(const std::vector<ObsEpoch>& base, DopplerSlipOptions o) {
  o.max_gap_s = std::max(o.max_gap_s, kBaseMaxGap_s);
  PhaseSlipScreen screen(o);
  BasePhaseArcs out;
  std::map<SatId, int> arc;
  out.arc.resize(base.size());
  for (size_t j = 0; j < base.size(); ++j) {
    const auto slips = screen.screen(base[j]);
    out.arc[j].resize(base[j].sats.size());
    for (size_t i = 0; i < slips.size(); ++i) {
      int& a = arc[base[j].sats[i].sat];
      if (slips[i]) ++a, out.started_by[{base[j].sats[i].sat, a}] = *slips[i];
      out.arc[j][i] = a;
    }
  }
  return out;
}

}  // namespace pednav::gnss
