// SPDX-License-Identifier: BSD-2-Clause
// Carrier phase in the tight coupling (fusion/carrier_update.hpp, docs/carrier.md §8).
#include "fusion/carrier_update.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "fusion/ambiguity.hpp"
#include "fusion/rtk_filter.hpp"
#include "gnss/least_squares.hpp"
#include "gnss/measurement.hpp"

namespace pednav::fusion {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kPhaseClockSigma_m = 10.0;  // common-mode σ of the phase rows (eq. 8.2)

}  // namespace

CarrierUpdater::CarrierUpdater(const gnss::NavData* nav, const std::vector<gnss::ObsEpoch>* base,
                               const EngineOptions& o)
    : nav_(nav), base_(base), o_(o), rover_screen_(o.carrier_slip) {
  slots_.resize(static_cast<size_t>(std::max(0, o.ambiguity_slots)));
  if (base) base_arcs_ = gnss::screen_base_phase(*base, o.carrier_slip);
}

double CarrierUpdater::base_clock_drift_mps(const gnss::ObsEpoch& base) const {
  std::vector<double> d;
  for (const gnss::SatObs& o : base.sats) {
    if (!std::isfinite(o.doppler_hz) || !std::isfinite(o.wavelength_m) || !std::isfinite(o.pseudorange_m)) continue;
    auto st = gnss::satellite_state_at_reception(*nav_, o.sat, base.time, o.pseudorange_m);
    if (!st) continue;
    const Vector3d u = (st->p_es_e - *o_.base_position_e).normalized();
    d.push_back(-o.wavelength_m * o.doppler_hz - u.dot(st->v_es_e) + kSpeedOfLight_mps * st->clock_drift_sps);
  }
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

void CarrierUpdater::screen_rover(const gnss::ObsEpoch& rover) {
  const auto slips = rover_screen_.screen(rover);
  for (size_t i = 0; i < rover.sats.size(); ++i) {
    if (slips[i]) ++rover_arc_[rover.sats[i].sat], rover_reason_[rover.sats[i].sat] = *slips[i];
  }
}

void CarrierUpdater::restart_all(ErrorStateFilter& f, gnss::SlipReason why, EngineSummary& sum) {
  for (size_t k = 0; k < slots_.size(); ++k) {
    if (!slots_[k].used) continue;
    ++sum.carrier.slips[static_cast<int>(why)];
    slots_[k] = Slot{};
    f.ambiguity_value(static_cast<int>(k)) = 0.0;
    f.restart_variable(f.ambiguity_offset() + static_cast<int>(k), 1.0);
  }
  consecutive_fixes_ = 0;
}

CarrierEpoch CarrierUpdater::update(ErrorStateFilter& f, const gnss::ObsEpoch& re, const gnss::ObsEpoch& be,
                                    int base_index, double age_s, const Vector3d& p_a_e, const LeverArm& arm,
                                    const Eigen::Matrix3d& C_pos_e, const std::vector<int>& clock_slot_of_system,
                                    const std::map<gnss::SatId, double>& code_sigma, EngineSummary& sum, int pos_col) {
  CarrierEpoch out;
  if (!nav_ || !o_.base_position_e || f.ambiguity_slots() == 0) return out;
  const int n = f.layout().dim();
  const int64_t t_ns = re.time.ns();
  const int64_t gap_ns = static_cast<int64_t>(o_.carrier_slip.max_gap_s * 1e9);
  // Slots not measured for longer than the gap limit are freed.
  for (auto& s : slots_) {
    if (s.used && t_ns - s.last_ns > gap_ns) {
      ++sum.carrier.slips[static_cast<int>(gnss::SlipReason::kGap)];
      s = Slot{};
    }
  }
  struct Row {
    gnss::SatId sat;
    int slot = -1;
    double residual = 0.0, sigma = 0.0, el = 0.0, lambda = 0.0;
    Eigen::RowVectorXd h;
    bool tested_out = false;
  };
  // The base epoch at its own time (eq. 1.1: the geometry of each receiver's own epoch), not the Doppler-propagated
  // copy the code rows use: a constant-Doppler extrapolation over the Galway base's 14-s gaps is tens of cycles off.
  const gnss::ObsEpoch& be0 = base_ && base_index >= 0 ? (*base_)[base_index] : be;
  // The base clock's change between its epoch and the rover's (docs/carrier.md eq. 8.2b): the code rows' differential
  // clock is at the rover epoch, the phase rows' base term at the base epoch. From the base's own Doppler: its clock
  // drift is the median over satellites of −λD − u·v_s + c ḋt_s (the base does not move); zero at a common epoch.
  const double base_dt_s = re.time - be0.time;
  if (base_dt_s != 0.0 && (base_index < 0 || base_index != drift_base_index_)) {  // once per base epoch
    drift_mps_ = base_clock_drift_mps(be0);
    drift_base_index_ = base_index;
  }
  const double base_clock_change_m = base_dt_s != 0.0 ? drift_mps_ * base_dt_s : 0.0;
  std::vector<Row> rows;
  for (const gnss::SatObs& so : re.sats) {
    const auto cs = code_sigma.find(so.sat);
    if (cs == code_sigma.end()) continue;  // its code row was not built (mask, no ephemeris, not at base, ...)
    if (!std::isfinite(so.carrier_cycles) || !std::isfinite(so.wavelength_m) || (so.lli & gnss::kLliHalfCycle)) continue;
    int bk = -1;
    for (size_t k = 0; k < be0.sats.size(); ++k) {
      if (be0.sats[k].sat == so.sat) bk = static_cast<int>(k);
    }
    if (bk < 0) continue;
    const gnss::SatObs& bo = be0.sats[bk];
    if (!std::isfinite(bo.carrier_cycles) || (bo.lli & gnss::kLliHalfCycle) || !std::isfinite(bo.pseudorange_m)) continue;
    const int sys = static_cast<int>(so.sat.system);
    const int clock_slot = sys < static_cast<int>(clock_slot_of_system.size()) ? clock_slot_of_system[sys] : -1;
    if (clock_slot < 0) continue;
    auto sr = gnss::satellite_state_at_reception(*nav_, so.sat, re.time, so.pseudorange_m);
    auto sb = gnss::satellite_state_at_reception(*nav_, so.sat, be0.time, bo.pseudorange_m);
    if (!sr || !sb) continue;
    // The base record of the matched base epoch carries its arc (a propagated copy keeps the record order).
    const int barc = base_ && base_index >= 0 ? base_arcs_.arc[base_index][bk] : 0;
    const int rarc = rover_arc_[so.sat];
    int k = -1;
    for (size_t i = 0; i < slots_.size(); ++i) {
      if (slots_[i].used && slots_[i].sat == so.sat) k = static_cast<int>(i);
    }
    if (k >= 0 && (slots_[k].rover_arc != rarc || slots_[k].base_arc != barc)) {
      gnss::SlipReason why = gnss::SlipReason::kLossOfLock;
      if (slots_[k].rover_arc != rarc) {
        if (auto it = rover_reason_.find(so.sat); it != rover_reason_.end()) why = it->second;
      } else if (auto b = base_arcs_.reason(so.sat, barc)) {
        why = *b;
      }
      ++sum.carrier.slips[static_cast<int>(why)];
      slots_[k] = Slot{};
      k = -1;
    }
    bool is_new = false;
    if (k < 0) {
      // The least recently used free slot (none free: this satellite's phase is left out this epoch).
      for (size_t i = 0; i < slots_.size(); ++i) {
        if (!slots_[i].used) { k = static_cast<int>(i); break; }
      }
      if (k < 0) { ++sum.carrier.no_free_slot; continue; }
      slots_[k].used = true;
      slots_[k].sat = so.sat;
      slots_[k].rover_arc = rarc;
      slots_[k].base_arc = barc;
      slots_[k].lock_epochs = 0;
      slots_[k].held = false;
      is_new = true;
    }
    slots_[k].last_ns = t_ns;
    gnss::SignalAtReceiver rs, bs;
    rs.sat = *sr;
    bs.sat = *sb;
    const double lambda = so.wavelength_m;
    rs.pseudorange_m = lambda * so.carrier_cycles;
    bs.pseudorange_m = lambda * bo.carrier_cycles;
    gnss::MeasurementRow ph = gnss::sd_carrier_phase(so.sat, rs, bs, p_a_e, *o_.base_position_e, f.clock(clock_slot));
    ph.residual -= base_clock_change_m;  // the base term at the rover epoch (eq. 8.2b)
    const double el = gnss::elevation_azimuth(p_a_e, sr->p_es_e).elevation;
    const double el_b = gnss::elevation_azimuth(*o_.base_position_e, sb->p_es_e).elevation;
    Row r;
    r.sat = so.sat;
    r.slot = k;
    r.el = el;
    r.lambda = lambda;
    r.sigma = std::hypot(gnss::carrier_sigma_m(o_.weights, o_.carrier_sigma_zenith_m, so.cn0_dbhz, el),
                         gnss::carrier_sigma_m(o_.weights, o_.carrier_sigma_zenith_m, bo.cn0_dbhz, el_b),
                         o_.carrier_base_age_sigma_mps * age_s);
    r.h = Eigen::RowVectorXd::Zero(n);
    r.h.segment<3>(pos_col) = ph.J_p;
    if (pos_col == ins::kPos.offset) r.h.segment<3>(ins::kAtt.offset) = ph.J_p * arm.d_arm_d_phi_e;  // docs/fusion.md eq. 14.2
    r.h(f.clock_offset(clock_slot)) = 1.0;
    const int ai = f.ambiguity_offset() + k;
    if (is_new) {
      // Eq. 4.4: the new ambiguity at (phase − predicted range)/λ with that prediction's variance plus the code's.
      const double var = (r.h * f.P() * r.h.transpose())(0, 0) + cs->second * cs->second +
                         (ph.J_p * C_pos_e * ph.J_p.transpose())(0, 0);
      f.ambiguity_value(k) = ph.residual / lambda;
      f.restart_variable(ai, var / (lambda * lambda));
    }
    r.h(ai) = lambda;
    r.residual = ph.residual - lambda * f.ambiguity_value(k);
    rows.push_back(std::move(r));
  }
  if (rows.empty()) return out;
  // The w-test of each phase row against the epoch (docs/carrier.md eq. 2.2) with the INS-predicted geometry: the
  // worst beyond the critical value is a slip — its ambiguity restarts and the test is redone.
  const double w_crit = std::sqrt(gnss::chi_square_quantile(o_.fault_probability, 1));
  const int m = static_cast<int>(rows.size());
  MatrixXd H(m, n), Jant(m, 3);
  VectorXd r(m), var(m);
  int held_slips = 0;
  MatrixXd Rm, Sinv, P;
  for (int iter = 0; iter <= m; ++iter) {
    P = f.P();
    for (int i = 0; i < m; ++i) {
      H.row(i) = rows[i].h;
      r(i) = rows[i].residual;
      var(i) = rows[i].sigma * rows[i].sigma;
      Jant.row(i) = rows[i].h.segment<3>(pos_col);
    }
    // The non-rigid antenna offset, common to every satellite, and the receiver clocks' phase term (eq. 8.2): the
    // phase rows use the base at its own epoch, the code rows the base moved to the rover epoch with its Doppler,
    // so their differential clocks differ by the base clock's change over the age; a common σ_c makes the phase
    // rows between-satellite differences that leave the clock to the code.
    Rm = Jant * C_pos_e * Jant.transpose();
    Rm.array() += kPhaseClockSigma_m * kPhaseClockSigma_m;
    Rm.diagonal() += var;
    const MatrixXd S = H * P * H.transpose() + Rm;
    const Eigen::LDLT<MatrixXd> ldlt(S);
    if (ldlt.info() != Eigen::Success) return out;
    Sinv = ldlt.solve(MatrixXd::Identity(m, m));
    const VectorXd t = Sinv * r;
    int worst = -1;
    double worst_w = w_crit;
    for (int i = 0; i < m; ++i) {
      if (rows[i].tested_out) continue;
      const double w = std::abs(t(i)) / std::sqrt(Sinv(i, i));
      if (w > worst_w) worst_w = w, worst = i;
    }
    if (worst < 0 || m < 2) break;
    Row& bad = rows[worst];
    ++sum.carrier.slips[static_cast<int>(gnss::SlipReason::kGeometry)];
    Slot& s = slots_[bad.slot];
    if (s.held) ++held_slips;
    s.held = false;
    s.lock_epochs = 0;
    const int ai = f.ambiguity_offset() + bad.slot;
    const double raw = bad.residual + bad.lambda * f.ambiguity_value(bad.slot);
    Eigen::RowVectorXd hg = bad.h;
    hg(ai) = 0.0;
    const double v = (hg * P * hg.transpose())(0, 0) + code_sigma.at(bad.sat) * code_sigma.at(bad.sat);
    f.ambiguity_value(bad.slot) = raw / bad.lambda;
    f.restart_variable(ai, v / (bad.lambda * bad.lambda));
    bad.residual = 0.0;
    bad.tested_out = true;
  }
  // The update with every phase row (Joseph form, recorded for the smoother).
  const VectorXd dx_upd = P * H.transpose() * (Sinv * r);
  if (!f.update(r, H, Rm)) return out;
  ++sum.carrier.epochs_with_phase;
  out.status = static_cast<int>(SolutionStatus::kFloat);
  out.n_phase = m;
  for (const Row& rw : rows) ++slots_[rw.slot].lock_epochs;
  if (held_slips >= 2) {
    ++sum.carrier.wrong_fix_detections;
    restart_all(f, gnss::SlipReason::kWrongFix, sum);
    return out;
  }
  // Integer resolution on the updated state (eqs. 3.1-3.6): the ambiguity entries of the state vector are the
  // nominal values (the error state is zero after the closed-loop update).
  std::vector<AmbiguityCandidate> cands;
  VectorXd x = VectorXd::Zero(n);
  for (const Row& rw : rows) {
    const int ai = f.ambiguity_offset() + rw.slot;
    x(ai) = f.ambiguity_value(rw.slot);
    const bool integer = gnss::integer_ambiguity_system(rw.sat.system) ||
                         (o_.ambiguity.glonass && rw.sat.system == gnss::System::kGlonass);
    cands.push_back({ai, rw.sat, rw.el, slots_[rw.slot].lock_epochs, integer});
  }
  ++sum.carrier.fix_attempts;
  const MatrixXd Pu = f.P();
  const AmbiguityFix fix = resolve_ambiguities(x, Pu, cands, o_.ambiguity);
  out.ratio = fix.ratio;
  if (!fix.fixed) {
    ++sum.carrier.not_fixed[fix.why_not];
    consecutive_fixes_ = 0;
    return out;
  }
  VectorXd xf = x;
  MatrixXd Pf = Pu;
  bool valid = condition_on_integers(xf, Pf, fix.D, fix.z, 0.0);
  if (valid) {
    // Eq. 3.7: each phase residual at the fixed state (the update's and the fix's corrections together).
    const VectorXd move = dx_upd + (xf - x);
    VectorXd e(m);
    for (int i = 0; i < m; ++i) e(i) = rows[i].residual - (rows[i].h * move)(0);
    // The common phase term of eq. 8.2 (σ_c: the differential clock of the phase rows is not the code's) is not
    // estimated: it stays in every residual of a constellation alike. The test is on the residuals less their
    // constellation's mean (between-satellite differences, which the integers are about).
    for (int i = 0; i < m; ++i) {
      double sum_e = 0.0;
      int count = 0;
      for (int j = 0; j < m; ++j) {
        if (rows[j].sat.system == rows[i].sat.system) sum_e += e(j), ++count;
      }
      const double d = count > 1 ? e(i) - sum_e / count : 0.0;
      if (std::abs(d) / rows[i].sigma > o_.ambiguity.validation_w) valid = false;
    }
  }
  if (!valid) {
    ++sum.carrier.fixes_rejected_by_validation;
    ++sum.carrier.not_fixed["validation"];
    consecutive_fixes_ = 0;
    if (std::any_of(slots_.begin(), slots_.end(), [](const Slot& s) { return s.used && s.held; })) {
      ++sum.carrier.wrong_fix_detections;
      restart_all(f, gnss::SlipReason::kWrongFix, sum);
    }
    return out;
  }
  ++consecutive_fixes_;
  out.n_fixed = static_cast<int>(fix.D.rows());
  if (consecutive_fixes_ < o_.ambiguity.hold_min_epochs) return out;  // float until the fix has repeated
  // The validated integers constrain the filter (docs/carrier.md eq. 8.1): D δx = ž − D x̂ with σ_hold.
  const VectorXd rz = fix.z - fix.D * x;
  const MatrixXd Rz = MatrixXd::Identity(fix.D.rows(), fix.D.rows()) * o_.ambiguity.hold_sigma_cycles *
                      o_.ambiguity.hold_sigma_cycles;
  if (f.update(rz, fix.D, Rz)) {
    ++sum.carrier.holds;
    out.status = static_cast<int>(SolutionStatus::kFixed);
    for (Slot& s : slots_) {
      if (s.used && std::find(fix.sats.begin(), fix.sats.end(), s.sat) != fix.sats.end()) s.held = true;
    }
  }
  return out;
}

}  // namespace pednav::fusion
