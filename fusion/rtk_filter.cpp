// SPDX-License-Identifier: BSD-2-Clause
// GNSS-only kinematic RTK (fusion/rtk_filter.hpp, docs/carrier.md §4).
#include "fusion/rtk_filter.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"
#include "fusion/glonass_ifb.hpp"
#include "fusion/kinematic_model.hpp"
#include "gnss/least_squares.hpp"

namespace pednav::fusion {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kInitClockSigma_m = 100.0;   // the clocks are white: re-initialized from the code every epoch
constexpr double kInitDriftSigma_mps = 10.0;
constexpr double kInitPosSigma_m = 10.0;
constexpr double kInitVelSigma_mps = 2.0;

}  // namespace

// One linearised row of the epoch: SD code, SD Doppler or SD phase.
struct RtkFilter::Row {
  enum Kind { kCode, kDoppler, kPhase } kind = kCode;
  int sat = -1;        // index into the epoch's satellite list
  int amb = -1;        // phase: index into amb_
  double residual = 0.0;
  double sigma = 0.0;
  Eigen::RowVectorXd h;
  bool active = true;
  bool tested_out = false;  // a phase row whose ambiguity was restarted this epoch: no further test
};

RtkFilter::RtkFilter(const gnss::NavData& nav, const std::vector<gnss::ObsEpoch>& base, const Vector3d& p_eb_e,
                     const RtkOptions& o)
    : nav_(nav), base_(base), p_eb_e_(p_eb_e), o_(o), rover_screen_(o.doppler_slip),
      base_arcs_(gnss::screen_base_phase(base, o.doppler_slip)) {
  // The base's phases are screened once, in time order (eq. 2.1), in the initializer above.
}

void RtkFilter::restart_state(int i, double value, double variance) {
  x_(i) = value;
  P_.row(i).setZero();
  P_.col(i).setZero();
  P_(i, i) = variance;
}

int RtkFilter::add_ambiguity(const gnss::SatId& sat, double value, double variance) {
  const int n = static_cast<int>(x_.size());
  x_.conservativeResize(n + 1);
  P_.conservativeResize(n + 1, n + 1);
  P_.row(n).setZero();
  P_.col(n).setZero();
  x_(n) = value;
  P_(n, n) = variance;
  Amb a;
  a.sat = sat;
  amb_.push_back(a);
  return static_cast<int>(amb_.size()) - 1;
}

void RtkFilter::remove_ambiguity(size_t k) {
  const int i = amb_index(k);
  const int n = static_cast<int>(x_.size());
  const int tail = n - i - 1;
  if (tail > 0) {
    x_.segment(i, tail) = x_.tail(tail).eval();
    P_.block(i, 0, tail, n) = P_.block(i + 1, 0, tail, n).eval();
    P_.block(0, i, n, tail) = P_.block(0, i + 1, n, tail).eval();
  }
  x_.conservativeResize(n - 1);
  P_.conservativeResize(n - 1, n - 1);
  amb_.erase(amb_.begin() + static_cast<std::ptrdiff_t>(k));
}

void RtkFilter::reset_all_ambiguities(gnss::SlipReason why) {
  for (size_t k = amb_.size(); k-- > 0;) {
    ++sum_.slips[static_cast<int>(why)];
    remove_ambiguity(k);
  }
  consecutive_fixes_ = 0;
}

void RtkFilter::predict(double dt) {
  // White acceleration (docs/carrier.md eq. 4.1).
  predict_white_acceleration(x_, P_, dt, o_.accel_sigma_horizontal_mps2, o_.accel_sigma_vertical_mps2);
}

RtkEpoch RtkFilter::process(const gnss::ObsEpoch& rover, int base_index) {
  RtkEpoch out;
  out.time = rover.time;
  ++sum_.epochs;
  // The rover's phases are screened at every epoch, base or not, so the history stays continuous.
  const auto rover_slips = rover_screen_.screen(rover);
  std::vector<std::optional<gnss::SlipReason>> slip_reason(rover.sats.size());
  for (size_t i = 0; i < rover.sats.size(); ++i) {
    if (rover_slips[i]) ++rover_arc_[rover.sats[i].sat], slip_reason[i] = rover_slips[i];
  }
  if (base_index < 0) {
    ++sum_.none;
    return out;
  }
  const gnss::ObsEpoch& be = base_[base_index];
  const double age = rover.time - be.time;
  out.base_age_s = age;

  if (!initialized_) {
    gnss::SolverOptions so;
    so.elevation_mask_rad = o_.elevation_mask_rad;
    so.min_cn0_dbhz = o_.min_cn0_dbhz;
    so.weights = o_.weights;
    so.fault_probability = o_.fault_probability;
    gnss::ObsEpoch filtered = rover;
    std::erase_if(filtered.sats, [&](const gnss::SatObs& s) { return system_slot(o_.systems, s.sat.system) < 0; });
    const auto sol = gnss::solve_epoch(nav_, filtered, &be, p_eb_e_, Vector3d::Zero(), so);
    if (!sol.ok()) {
      ++sum_.none;
      return out;
    }
    const int n = 7 + n_clk();
    x_ = VectorXd::Zero(n);
    P_ = MatrixXd::Zero(n, n);
    x_.segment<3>(0) = sol.p_ea_e;
    if (sol.velocity_ok) x_.segment<3>(3) = sol.v_ea_e;
    P_.diagonal().segment<3>(0).setConstant(kInitPosSigma_m * kInitPosSigma_m);
    P_.diagonal().segment<3>(3).setConstant(kInitVelSigma_mps * kInitVelSigma_mps);
    for (int s = 0; s < n_clk(); ++s) P_(clock_index(s), clock_index(s)) = kInitClockSigma_m * kInitClockSigma_m;
    P_(drift_index(), drift_index()) = kInitDriftSigma_mps * kInitDriftSigma_mps;
    amb_.clear();
    initialized_ = true;
    t_prev_ = rover.time;
  }
  predict(rover.time - t_prev_);
  t_prev_ = rover.time;

  // The epoch's satellites: rover and base records, satellite states, elevations, σ's.
  struct Sat {
    const gnss::SatObs* r = nullptr;
    const gnss::SatObs* b = nullptr;
    int slot = -1, base_rec = -1;
    gnss::SignalAtReceiver rs, bs;
    double el = 0.0;
    double sigma_code = 0.0, sigma_dopp = 0.0, sigma_phase = 0.0;
  };
  std::vector<Sat> sats;
  sats.reserve(rover.sats.size());
  const Vector3d p0 = x_.segment<3>(0);
  std::vector<int> sat_of_record(rover.sats.size(), -1);
  for (size_t i = 0; i < rover.sats.size(); ++i) {
    const gnss::SatObs& so = rover.sats[i];
    Sat s;
    s.slot = system_slot(o_.systems, so.sat.system);
    if (s.slot < 0 || !std::isfinite(so.pseudorange_m)) continue;
    if (std::isfinite(so.cn0_dbhz) && so.cn0_dbhz < o_.min_cn0_dbhz) continue;
    for (size_t k = 0; k < be.sats.size(); ++k) {
      if (be.sats[k].sat == so.sat) s.base_rec = static_cast<int>(k);
    }
    if (s.base_rec < 0 || !std::isfinite(be.sats[s.base_rec].pseudorange_m)) continue;
    s.r = &so;
    s.b = &be.sats[s.base_rec];
    auto sr = gnss::satellite_state_at_reception(nav_, so.sat, rover.time, so.pseudorange_m);
    auto sb = gnss::satellite_state_at_reception(nav_, so.sat, be.time, s.b->pseudorange_m);
    if (!sr || !sb) continue;
    s.rs.sat = *sr;
    s.bs.sat = *sb;
    s.el = gnss::elevation_azimuth(p0, sr->p_es_e).elevation;
    if (s.el < o_.elevation_mask_rad) continue;
    const double el_b = gnss::elevation_azimuth(p_eb_e_, sb->p_es_e).elevation;
    const double glo = so.sat.system == gnss::System::kGlonass ? o_.weights.glonass_code_factor : 1.0;
    s.sigma_code = std::hypot(glo * gnss::measurement_sigma(o_.weights, so.cn0_dbhz, s.el, false),
                              glo * gnss::measurement_sigma(o_.weights, s.b->cn0_dbhz, el_b, false),
                              o_.code_base_age_sigma_mps * age);
    s.sigma_dopp = std::hypot(gnss::measurement_sigma(o_.weights, so.cn0_dbhz, s.el, true),
                              gnss::measurement_sigma(o_.weights, s.b->cn0_dbhz, el_b, true));
    s.sigma_phase = std::hypot(gnss::carrier_sigma_m(o_.weights, o_.carrier_sigma_zenith_m, so.cn0_dbhz, s.el),
                               gnss::carrier_sigma_m(o_.weights, o_.carrier_sigma_zenith_m, s.b->cn0_dbhz, el_b),
                               o_.base_age_sigma_mps * age);
    sat_of_record[i] = static_cast<int>(sats.size());
    sats.push_back(s);
  }
  if (sats.size() < 4) {
    ++sum_.none;
    return out;
  }
  const int n_before_amb = 7 + n_clk();
  // The clocks are white (eq. 4.2): each restarts at the median SD code residual of its constellation, the drift at
  // the median Doppler residual.
  for (int slot = 0; slot < n_clk(); ++slot) {
    std::vector<double> res;
    for (const Sat& s : sats) {
      if (s.slot != slot) continue;
      gnss::SignalAtReceiver rs = s.rs, bs = s.bs;
      rs.pseudorange_m = s.r->pseudorange_m;
      bs.pseudorange_m = s.b->pseudorange_m;
      res.push_back(gnss::sd_pseudorange(s.r->sat, rs, bs, p0, p_eb_e_, x_(clock_index(slot))).residual);
    }
    if (!res.empty()) restart_state(clock_index(slot), x_(clock_index(slot)) + median_of(res), kInitClockSigma_m * kInitClockSigma_m);
  }
  {
    std::vector<double> res;
    for (const Sat& s : sats) {
      gnss::SignalAtReceiver rs = s.rs, bs = s.bs;
      rs.range_rate_mps = -s.r->wavelength_m * s.r->doppler_hz;
      bs.range_rate_mps = -s.b->wavelength_m * s.b->doppler_hz;
      if (!std::isfinite(rs.range_rate_mps) || !std::isfinite(bs.range_rate_mps)) continue;
      res.push_back(gnss::sd_range_rate(s.r->sat, rs, bs, p0, x_.segment<3>(3), p_eb_e_, x_(drift_index())).residual);
    }
    if (!res.empty()) restart_state(drift_index(), x_(drift_index()) + median_of(res), kInitDriftSigma_mps * kInitDriftSigma_mps);
  }

  // Ambiguities: a satellite's arc (rover and base) changed → restart; not measured for max_gap_s → removed.
  for (size_t k = amb_.size(); k-- > 0;) {
    if (rover.time - amb_[k].last > o_.doppler_slip.max_gap_s) {
      ++sum_.slips[static_cast<int>(gnss::SlipReason::kGap)];
      remove_ambiguity(k);
    }
  }
  std::vector<int> amb_of_sat(sats.size(), -1);
  std::vector<bool> new_amb(sats.size(), false);
  std::vector<bool> has_phase(sats.size(), false);
  auto find_amb = [&](const gnss::SatId& sat) {
    for (size_t a = 0; a < amb_.size(); ++a) {
      if (amb_[a].sat == sat) return static_cast<int>(a);
    }
    return -1;
  };
  // First the restarts (removal shifts the indices), then the lookup of every satellite's ambiguity.
  for (size_t i = 0; i < rover.sats.size(); ++i) {
    const int si = sat_of_record[i];
    if (si < 0) continue;
    const Sat& s = sats[si];
    has_phase[si] = std::isfinite(s.r->carrier_cycles) && std::isfinite(s.b->carrier_cycles) &&
                    std::isfinite(s.r->wavelength_m) && !(s.r->lli & gnss::kLliHalfCycle) &&
                    !(s.b->lli & gnss::kLliHalfCycle);
    if (!has_phase[si]) continue;
    const int k = find_amb(s.r->sat);
    const int rarc = rover_arc_[s.r->sat];
    const int barc = base_arcs_.arc[base_index][s.base_rec];
    if (k >= 0 && (amb_[k].rover_arc != rarc || amb_[k].base_arc != barc)) {
      gnss::SlipReason why = gnss::SlipReason::kLossOfLock;
      if (slip_reason[i]) {
        why = *slip_reason[i];
      } else if (auto b = base_arcs_.reason(s.r->sat, barc)) {
        why = *b;  // the base's slip (the newest one when several base epochs were skipped)
      }
      ++sum_.slips[static_cast<int>(why)];
      remove_ambiguity(static_cast<size_t>(k));
    }
  }
  for (size_t i = 0; i < rover.sats.size(); ++i) {
    const int si = sat_of_record[i];
    if (si < 0 || !has_phase[si]) continue;
    const Sat& s = sats[si];
    int k = find_amb(s.r->sat);
    if (k < 0) {
      k = add_ambiguity(s.r->sat, 0.0, 1.0);
      amb_[k].rover_arc = rover_arc_[s.r->sat];
      amb_[k].base_arc = base_arcs_.arc[base_index][s.base_rec];
      new_amb[si] = true;
    }
    amb_of_sat[si] = k;
  }
  // Rows, linearised at the predicted state (eqs. 1.1, 4.3).
  const int n = static_cast<int>(x_.size());
  std::vector<Row> rows;
  rows.reserve(3 * sats.size());
  for (size_t si = 0; si < sats.size(); ++si) {
    const Sat& s = sats[si];
    gnss::SignalAtReceiver rs = s.rs, bs = s.bs;
    rs.pseudorange_m = s.r->pseudorange_m;
    bs.pseudorange_m = s.b->pseudorange_m;
    const gnss::MeasurementRow code = gnss::sd_pseudorange(s.r->sat, rs, bs, p0, p_eb_e_, x_(clock_index(s.slot)));
    Row rc;
    rc.kind = Row::kCode;
    rc.sat = static_cast<int>(si);
    rc.residual = code.residual;
    rc.sigma = s.sigma_code;
    rc.h = Eigen::RowVectorXd::Zero(n);
    rc.h.segment<3>(0) = code.J_p;
    rc.h(clock_index(s.slot)) = 1.0;
    rows.push_back(rc);
    rs.range_rate_mps = -s.r->wavelength_m * s.r->doppler_hz;
    bs.range_rate_mps = -s.b->wavelength_m * s.b->doppler_hz;
    if (o_.use_doppler && std::isfinite(rs.range_rate_mps) && std::isfinite(bs.range_rate_mps)) {
      const gnss::MeasurementRow rate =
          gnss::sd_range_rate(s.r->sat, rs, bs, p0, x_.segment<3>(3), p_eb_e_, x_(drift_index()));
      Row rd;
      rd.kind = Row::kDoppler;
      rd.sat = static_cast<int>(si);
      rd.residual = rate.residual;
      rd.sigma = s.sigma_dopp;
      rd.h = Eigen::RowVectorXd::Zero(n);
      rd.h.segment<3>(0) = rate.J_p;
      rd.h.segment<3>(3) = rate.J_v;
      rd.h(drift_index()) = 1.0;
      rows.push_back(rd);
    }
    const int k = amb_of_sat[si];
    if (k < 0) continue;
    const double lambda = s.r->wavelength_m;
    rs.pseudorange_m = lambda * s.r->carrier_cycles;
    bs.pseudorange_m = lambda * s.b->carrier_cycles;
    const gnss::MeasurementRow ph = gnss::sd_carrier_phase(s.r->sat, rs, bs, p0, p_eb_e_, x_(clock_index(s.slot)));
    Row rp;
    rp.kind = Row::kPhase;
    rp.sat = static_cast<int>(si);
    rp.amb = k;
    rp.sigma = s.sigma_phase;
    rp.h = Eigen::RowVectorXd::Zero(n);
    rp.h.segment<3>(0) = ph.J_p;
    rp.h(clock_index(s.slot)) = 1.0;
    const int ai = amb_index(static_cast<size_t>(k));
    if (new_amb[si]) {
      // A new ambiguity starts at the phase minus the predicted range, with the prediction's variance plus the
      // code's (eq. 4.4): the first epoch of an arc carries no phase information of its own.
      const double var = (rp.h * P_ * rp.h.transpose())(0, 0) + s.sigma_code * s.sigma_code;
      restart_state(ai, ph.residual / lambda, var / (lambda * lambda));
    }
    rp.h(ai) = lambda;
    rp.residual = ph.residual - lambda * x_(ai);
    rows.push_back(rp);
  }

  // Update with fault detection (eq. 4.5): the w-test of each row against the whole epoch, w_i = (S⁻¹ν)_i /
  // √(S⁻¹)_ii; the worst beyond the critical value is a code/Doppler fault (row excluded) or a phase slip (its
  // ambiguity restarted), and the update is redone.
  const double w_crit = std::sqrt(gnss::chi_square_quantile(o_.fault_probability, 1));
  const VectorXd x_pre = x_;
  VectorXd dx;
  MatrixXd P_post;
  int held_slips = 0;
  WTestPass pass;
  for (size_t iter = 0; iter <= rows.size(); ++iter) {
    if (!w_test_pass(rows, P_, pass)) {
      ++sum_.none;
      return out;
    }
    const std::vector<int>& act = pass.act;
    const int m = static_cast<int>(act.size());
    const int worst = w_test_worst(pass, w_crit, [&](int k) { return rows[k].tested_out; });
    if (worst >= 0 && m > 4) {
      Row& bad = rows[act[worst]];
      if (bad.kind == Row::kPhase) {
        ++sum_.slips[static_cast<int>(gnss::SlipReason::kGeometry)];
        if (amb_[bad.amb].held) ++held_slips;
        amb_[bad.amb].held = false;
        amb_[bad.amb].lock_epochs = 0;
        const int ai = amb_index(static_cast<size_t>(bad.amb));
        const Eigen::RowVectorXd hg = bad.h - bad.h(ai) * Eigen::RowVectorXd::Unit(n, ai);
        const double lambda = bad.h(ai);
        const double var = (hg * P_ * hg.transpose())(0, 0) + sats[bad.sat].sigma_code * sats[bad.sat].sigma_code;
        const double raw = bad.residual + lambda * x_(ai);  // residual without the ambiguity
        restart_state(ai, raw / lambda, var / (lambda * lambda));
        bad.residual = raw - lambda * x_(ai);
        bad.tested_out = true;
      } else {
        bad.active = false;
        ++(bad.kind == Row::kCode ? sum_.code_rows_excluded : sum_.doppler_rows_excluded);
        ++out.n_rejected;
      }
      continue;
    }
    joseph_update(P_, pass, dx, P_post);
    break;
  }
  if (dx.size() != n) {
    ++sum_.none;
    return out;
  }
  x_ += dx;
  P_ = 0.5 * (P_post + P_post.transpose());
  if (held_slips >= 2) {
    // Two held ambiguities slipped at once: the held integers were wrong (or the sky changed under them); undo the
    // hold by restarting every ambiguity (eq. 3.8).
    ++sum_.wrong_fix_detections;
    reset_all_ambiguities(gnss::SlipReason::kWrongFix);
  }
  for (const Row& rw : rows) {
    if (!rw.active) continue;
    if (rw.kind == Row::kCode) ++out.n_sats;
    if (rw.kind == Row::kPhase && static_cast<size_t>(rw.amb) < amb_.size()) {
      ++out.n_phase;
      amb_[rw.amb].last = rover.time;
      ++amb_[rw.amb].lock_epochs;
    }
  }
  out.status = out.n_phase > 0 ? SolutionStatus::kFloat : SolutionStatus::kCode;
  out.p_ea_e = x_.segment<3>(0);
  out.v_ea_e = x_.segment<3>(3);
  out.cov_p_e = P_.block<3, 3>(0, 0);

  // Integer resolution (eqs. 3.1-3.6) and the validation of the fixed solution (eq. 3.7).
  std::vector<AmbiguityCandidate> cands;
  for (const Row& rw : rows) {
    if (!rw.active || rw.kind != Row::kPhase || static_cast<size_t>(rw.amb) >= amb_.size()) continue;
    const Amb& a = amb_[rw.amb];
    const bool glonass = a.sat.system == gnss::System::kGlonass;
    const bool integer = gnss::integer_ambiguity_system(a.sat.system) ||
                         (glonass && (o_.ar.glonass || (o_.ar.glonass_ifb_search && ifb_.beta_m())));
    const int ai = amb_index(static_cast<size_t>(rw.amb));
    cands.push_back({ai, a.sat, sats[rw.sat].el, a.lock_epochs, integer, rw.h(ai)});
  }
  if (!cands.empty() && x_.size() > n_before_amb) {
    ++sum_.fix_attempts;
    // GLONASS inter-frequency bias rate β (eqs. 3.9-3.11): searched while unknown, then removed before the resolution.
    if (o_.ar.glonass_ifb_search && !o_.ar.glonass && !ifb_.beta_m()) {
      if (ifb_.search(x_, P_, cands, o_.ar)) {
        sum_.glonass_ifb_m_per_channel = ifb_.beta_m();
        sum_.glonass_ifb_found_s = rover.time - t_first_.value_or(rover.time);
        for (auto& c : cands) c.integer = c.integer || c.sat.system == gnss::System::kGlonass;
      }
      sum_.glonass_ifb_searches = ifb_.searches();
      sum_.glonass_ifb_votes = ifb_.votes_cast();
    }
    const VectorXd ifb = o_.ar.glonass_ifb_search && ifb_.beta_m()
                             ? glonass_ifb_offsets(static_cast<int>(x_.size()), cands, *ifb_.beta_m())
                             : VectorXd::Zero(x_.size());
    const AmbiguityFix fix = resolve_ambiguities(x_ - ifb, P_, cands, o_.ar);
    out.ratio = fix.ratio;
    if (!fix.fixed) {
      ++sum_.not_fixed[fix.why_not];
      consecutive_fixes_ = 0;
    } else {
      VectorXd xf = x_ - ifb;
      MatrixXd Pf = P_;
      bool valid = condition_on_integers(xf, Pf, fix.D, fix.z, 0.0);
      xf += ifb;  // the float ambiguity states keep β k / λ (eq. 3.9)
      if (valid) {
        const VectorXd move = xf - x_pre;
        for (const Row& rw : rows) {
          if (!rw.active || rw.kind != Row::kPhase) continue;
          const double e = rw.residual - (rw.h * move)(0);
          if (std::abs(e) / rw.sigma > o_.ar.validation_w) valid = false;
        }
      }
      if (!valid) {
        ++sum_.fixes_rejected_by_validation;
        ++sum_.not_fixed["validation"];
        consecutive_fixes_ = 0;
        bool any_held = false;
        for (const Amb& a : amb_) any_held |= a.held;
        if (any_held) {
          ++sum_.wrong_fix_detections;
          reset_all_ambiguities(gnss::SlipReason::kWrongFix);
        }
      } else {
        out.status = SolutionStatus::kFixed;
        out.n_fixed = static_cast<int>(fix.D.rows());
        out.p_ea_e = xf.segment<3>(0);
        out.v_ea_e = xf.segment<3>(3);
        out.cov_p_e = Pf.block<3, 3>(0, 0);
        ++consecutive_fixes_;
        x_ -= ifb;
        const bool held = o_.ar.hold && consecutive_fixes_ >= o_.ar.hold_min_epochs &&
                          condition_on_integers(x_, P_, fix.D, fix.z, o_.ar.hold_sigma_cycles);
        x_ += ifb;
        if (held) {
          ++sum_.holds;
          for (Amb& a : amb_) {
            if (std::find(fix.sats.begin(), fix.sats.end(), a.sat) != fix.sats.end()) a.held = true;
          }
        }
      }
    }
  }
  if (!t_first_) t_first_ = rover.time;
  if (out.status == SolutionStatus::kFixed && !sum_.time_to_first_fix_s) sum_.time_to_first_fix_s = rover.time - *t_first_;
  switch (out.status) {
    case SolutionStatus::kFixed: ++sum_.fixed; break;
    case SolutionStatus::kFloat: ++sum_.float_; break;
    case SolutionStatus::kCode: ++sum_.code; break;
    default: ++sum_.none; break;
  }
  return out;
}

}  // namespace pednav::fusion
