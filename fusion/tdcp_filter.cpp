// SPDX-License-Identifier: BSD-2-Clause
// GNSS-only kinematic filter with time-differenced carrier phase (fusion/tdcp_filter.hpp, docs/carrier.md §9).
#include "fusion/tdcp_filter.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "fusion/kinematic_model.hpp"
#include "gnss/least_squares.hpp"

namespace pednav::fusion {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kInitClockSigma_m = 100.0;  // the clocks are white: restarted from the rows every epoch
constexpr double kInitDriftSigma_mps = 10.0;
constexpr double kInitPosSigma_m = 10.0;
constexpr double kInitVelSigma_mps = 2.0;

struct Row {
  enum Kind { kCode, kDoppler, kTdcp } kind = kCode;
  gnss::SatId sat;
  double residual = 0.0;
  double sigma = 0.0;
  Eigen::RowVectorXd h;
  bool active = true;
};

}  // namespace

TdcpFilter::TdcpFilter(const gnss::NavData& nav, const TdcpOptions& o) : nav_(nav), o_(o), screen_(o.doppler_slip) {}

void TdcpFilter::restart_state(int i, double value, double variance) {
  x_(i) = value;
  P_.row(i).setZero();
  P_.col(i).setZero();
  P_(i, i) = variance;
}

void TdcpFilter::predict(double dt) {
  // White acceleration (docs/carrier.md eq. 4.1) on p, v; the clone is a constant between epochs (eq. 9.3).
  predict_white_acceleration(x_, P_, dt, o_.accel_sigma_horizontal_mps2, o_.accel_sigma_vertical_mps2);
}

void TdcpFilter::clone_position() {
  // Eq. 9.3: the clone becomes a copy of the position (x_c = x_p, rows and columns of P copied).
  x_.segment<3>(kClone) = x_.segment<3>(0);
  P_.middleRows<3>(kClone) = P_.middleRows<3>(0);
  P_.middleCols<3>(kClone) = P_.middleCols<3>(0);
}

TdcpEpoch TdcpFilter::process(const gnss::ObsEpoch& rover, bool use_code) {
  TdcpEpoch out;
  out.time = rover.time;
  ++sum_.epochs;
  // Every epoch's phases are screened (LLI, half-cycle flag changes, gap, integrated Doppler: eq. 2.1) so each
  // satellite's arc stays continuous whether or not the epoch is solved.
  const auto slips = screen_.screen(rover);
  for (size_t i = 0; i < rover.sats.size(); ++i) {
    if (slips[i]) {
      ++arc_[rover.sats[i].sat];
      if (prev_.count(rover.sats[i].sat)) ++sum_.slips[static_cast<int>(*slips[i])];
    }
  }

  if (!initialized_) {
    if (!use_code) return out;
    gnss::SolverOptions so;
    so.elevation_mask_rad = o_.elevation_mask_rad;
    so.min_cn0_dbhz = o_.min_cn0_dbhz;
    so.weights = o_.weights;
    so.fault_probability = o_.fault_probability;
    gnss::ObsEpoch filtered = rover;
    std::erase_if(filtered.sats, [&](const gnss::SatObs& s) { return system_slot(o_.systems, s.sat.system) < 0; });
    const auto sol = gnss::solve_epoch(nav_, filtered, nullptr, Vector3d::Zero(), Vector3d::Zero(), so);
    if (!sol.ok()) return out;
    const int n = 10 + 2 * n_clk();
    x_ = VectorXd::Zero(n);
    P_ = MatrixXd::Zero(n, n);
    x_.segment<3>(0) = sol.p_ea_e;
    if (sol.velocity_ok) x_.segment<3>(3) = sol.v_ea_e;
    P_.diagonal().segment<3>(0).setConstant(kInitPosSigma_m * kInitPosSigma_m);
    P_.diagonal().segment<3>(3).setConstant(kInitVelSigma_mps * kInitVelSigma_mps);
    for (int s = 0; s < n_clk(); ++s) {
      P_(clock_index(s), clock_index(s)) = kInitClockSigma_m * kInitClockSigma_m;
      P_(change_index(s), change_index(s)) = kInitClockSigma_m * kInitClockSigma_m;
    }
    P_(drift_index(), drift_index()) = kInitDriftSigma_mps * kInitDriftSigma_mps;
    clone_position();
    prev_.clear();
    initialized_ = true;
    t_prev_ = rover.time;
  }
  const double dt = rover.time - t_prev_;
  predict(dt);
  t_prev_ = rover.time;

  // The epoch's satellites with their states, modelled delays and σ's.
  struct Sat {
    const gnss::SatObs* r = nullptr;
    int slot = -1;
    gnss::SignalAtReceiver rs;
    double el = 0.0, iono = 0.0, tropo = 0.0;
    double sigma_code = 0.0, sigma_dopp = 0.0, sigma_phase = 0.0;
    bool phase = false;
  };
  std::vector<Sat> sats;
  sats.reserve(rover.sats.size());
  const Vector3d p0 = x_.segment<3>(0);
  const Vector3d v0 = x_.segment<3>(3);
  const Geodetic llh = geodetic_from_ecef(p0);
  for (const gnss::SatObs& so : rover.sats) {
    Sat s;
    s.slot = system_slot(o_.systems, so.sat.system);
    if (s.slot < 0 || !std::isfinite(so.pseudorange_m)) continue;
    if (std::isfinite(so.cn0_dbhz) && so.cn0_dbhz < o_.min_cn0_dbhz) continue;
    auto sr = gnss::satellite_state_at_reception(nav_, so.sat, rover.time, so.pseudorange_m);
    if (!sr) continue;
    s.r = &so;
    s.rs.sat = *sr;
    const gnss::ElevationAzimuth ea = gnss::elevation_azimuth(p0, sr->p_es_e);
    s.el = ea.elevation;
    if (s.el < o_.elevation_mask_rad) continue;
    s.iono = nav_.has_klobuchar ? gnss::klobuchar_delay_m(nav_.klobuchar, rover.time, llh, ea) : 0.0;
    s.tropo = gnss::saastamoinen_delay_m(llh, s.el);
    const double glo = so.sat.system == gnss::System::kGlonass ? o_.weights.glonass_code_factor : 1.0;
    s.sigma_code = glo * gnss::measurement_sigma(o_.weights, so.cn0_dbhz, s.el, false);
    s.sigma_dopp = gnss::measurement_sigma(o_.weights, so.cn0_dbhz, s.el, true);
    s.sigma_phase = gnss::carrier_sigma_m(o_.weights, o_.carrier_sigma_zenith_m, so.cn0_dbhz, s.el);
    s.phase = o_.use_phase && std::isfinite(so.carrier_cycles) && std::isfinite(so.wavelength_m) &&
              !(so.lli & gnss::kLliHalfCycle);
    sats.push_back(s);
  }

  // Rows at the predicted state (eqs. 4.3, 9.1). A TDCP row needs the satellite's phase at the previous processed
  // epoch in the same arc.
  const int n = static_cast<int>(x_.size());
  std::vector<Row> rows;
  rows.reserve(3 * sats.size());
  std::vector<std::vector<double>> code_res(n_clk()), tdcp_res(n_clk());
  std::vector<double> dopp_res;
  for (const Sat& s : sats) {
    gnss::SignalAtReceiver rs = s.rs;
    rs.pseudorange_m = s.r->pseudorange_m;
    rs.range_rate_mps = -s.r->wavelength_m * s.r->doppler_hz;
    if (use_code) {
      const gnss::MeasurementRow code = gnss::ud_pseudorange(s.r->sat, rs, p0, x_(clock_index(s.slot)), s.iono, s.tropo);
      Row rc;
      rc.kind = Row::kCode;
      rc.sat = s.r->sat;
      rc.residual = code.residual;
      rc.sigma = s.sigma_code;
      rc.h = Eigen::RowVectorXd::Zero(n);
      rc.h.segment<3>(0) = code.J_p;
      rc.h(clock_index(s.slot)) = 1.0;
      code_res[s.slot].push_back(rc.residual);
      rows.push_back(rc);
    }
    if (o_.use_doppler && std::isfinite(rs.range_rate_mps)) {
      const gnss::MeasurementRow rate = gnss::ud_range_rate(s.r->sat, rs, p0, v0, x_(drift_index()));
      Row rd;
      rd.kind = Row::kDoppler;
      rd.sat = s.r->sat;
      rd.residual = rate.residual;
      rd.sigma = s.sigma_dopp;
      rd.h = Eigen::RowVectorXd::Zero(n);
      rd.h.segment<3>(0) = rate.J_p;
      rd.h.segment<3>(3) = rate.J_v;
      rd.h(drift_index()) = 1.0;
      dopp_res.push_back(rd.residual);
      rows.push_back(rd);
    }
    if (!s.phase) continue;
    const auto it = prev_.find(s.r->sat);
    if (it == prev_.end() || it->second.arc != arc_[s.r->sat]) continue;
    gnss::SignalAtReceiver now = s.rs;
    now.pseudorange_m = s.r->wavelength_m * s.r->carrier_cycles;
    const gnss::MeasurementRow td = gnss::td_carrier_phase(s.r->sat, now, it->second.signal, p0,
                                                           x_.segment<3>(kClone), x_(change_index(s.slot)));
    Row rt;
    rt.kind = Row::kTdcp;
    rt.sat = s.r->sat;
    rt.residual = td.residual;
    rt.sigma = std::hypot(s.sigma_phase, it->second.sigma_m);
    rt.h = Eigen::RowVectorXd::Zero(n);
    rt.h.segment<3>(0) = td.J_p;
    rt.h.segment<3>(kClone) = td.J_v;
    rt.h(change_index(s.slot)) = 1.0;
    tdcp_res[s.slot].push_back(rt.residual);
    rows.push_back(rt);
  }
  // White clocks (eq. 4.2, 9.4): each restarts at the median residual of its rows.
  for (int s = 0; s < n_clk(); ++s) {
    const double var = kInitClockSigma_m * kInitClockSigma_m;
    const double dc = median_of(code_res[s]), dt_c = median_of(tdcp_res[s]);
    restart_state(clock_index(s), x_(clock_index(s)) + dc, var);
    restart_state(change_index(s), x_(change_index(s)) + dt_c, var);
    for (Row& r : rows) {
      if (system_slot(o_.systems, r.sat.system) != s) continue;
      if (r.kind == Row::kCode) r.residual -= dc;
      if (r.kind == Row::kTdcp) r.residual -= dt_c;
    }
  }
  {
    const double dd = median_of(dopp_res);
    restart_state(drift_index(), x_(drift_index()) + dd, kInitDriftSigma_mps * kInitDriftSigma_mps);
    for (Row& r : rows) {
      if (r.kind == Row::kDoppler) r.residual -= dd;
    }
  }
  if (rows.empty()) {
    clone_position();
    prev_.clear();
    return out;
  }

  // Update with fault detection (eq. 4.5): the w-test of each row against the epoch; the worst beyond the critical
  // value is excluded (a TDCP row's failure is an undetected slip: its satellite starts a new arc) and the update is
  // redone.
  const double w_crit = std::sqrt(gnss::chi_square_quantile(o_.fault_probability, 1));
  VectorXd dx;
  MatrixXd P_post;
  WTestPass pass;
  for (size_t iter = 0; iter <= rows.size(); ++iter) {
    if (std::none_of(rows.begin(), rows.end(), [](const Row& w) { return w.active; })) break;
    if (!w_test_pass(rows, P_, pass)) break;
    const std::vector<int>& act = pass.act;
    const int m = static_cast<int>(act.size());
    const int worst = w_test_worst(pass, w_crit, [](int) { return false; });
    if (worst >= 0 && m > 4) {
      Row& bad = rows[act[worst]];
      bad.active = false;
      if (bad.kind == Row::kTdcp) {
        ++sum_.slips[static_cast<int>(gnss::SlipReason::kGeometry)];
        ++arc_[bad.sat];
      } else {
        ++(bad.kind == Row::kCode ? sum_.code_rows_excluded : sum_.doppler_rows_excluded);
        ++out.n_rejected;
      }
      continue;
    }
    joseph_update(P_, pass, dx, P_post);
    break;
  }
  if (dx.size() == n) {
    x_ += dx;
    P_ = 0.5 * (P_post + P_post.transpose());
    for (const Row& rw : rows) {
      if (!rw.active) continue;
      if (rw.kind == Row::kCode) ++out.n_sats;
      if (rw.kind == Row::kTdcp) ++out.n_tdcp;
    }
  }
  // Without code the position is carried by the displacement alone; it is a solution once the filter has one.
  int n_dopp = 0;
  for (const Row& rw : rows) n_dopp += rw.active && rw.kind == Row::kDoppler;
  out.ok = dx.size() == n && (out.n_sats >= 4 || (!use_code && std::max(out.n_tdcp, n_dopp) >= 4));
  if (out.ok) {
    ++sum_.solved;
    if (out.n_tdcp > 0) ++sum_.tdcp_epochs;
    sum_.tdcp_rows += out.n_tdcp;
  }
  out.p_ea_e = x_.segment<3>(0);
  out.v_ea_e = x_.segment<3>(3);
  out.cov_p_e = P_.block<3, 3>(0, 0);
  out.cov_v_e = P_.block<3, 3>(3, 3);
  out.dt_s = dt;
  out.displacement_e = x_.segment<3>(0) - x_.segment<3>(kClone);

  // The epoch's phases become the previous ones, and the clone the position they belong to (eq. 9.3).
  prev_.clear();
  for (const Sat& s : sats) {
    if (!s.phase) continue;
    PhaseRecord pr;
    pr.arc = arc_[s.r->sat];
    pr.time = rover.time;
    pr.signal = s.rs;
    pr.signal.pseudorange_m = s.r->wavelength_m * s.r->carrier_cycles;
    pr.sigma_m = s.sigma_phase;
    prev_[s.r->sat] = pr;
  }
  clone_position();
  return out;
}

}  // namespace pednav::fusion
