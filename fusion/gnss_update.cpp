// SPDX-License-Identifier: BSD-2-Clause
// The GNSS measurement update of one rover epoch (fusion/gnss_update.hpp).
#include "fusion/gnss_update.hpp"

#include <algorithm>
#include <cmath>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/antenna_state.hpp"
#include "fusion/lever_arm.hpp"
#include "gnss/ephemeris.hpp"
#include "gnss/least_squares.hpp"
#include "gnss/measurement.hpp"

namespace pednav::fusion {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

int system_slot(const std::vector<gnss::System>& systems, gnss::System s) {
  for (size_t i = 0; i < systems.size(); ++i) {
    if (systems[i] == s) return static_cast<int>(i);
  }
  return -1;
}

// Median of v (reorders v; no copy).
double median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

GnssEpochUpdater::GnssEpochUpdater(const EngineInputs& in, const EngineOptions& o)
    : in_(in), o_(o), faults_(o.fault_probability, o.fault_window_epochs) {
  if (o.mode == Mode::kTightlyCoupled && in.rover && in.base && o.base_position_e) {
    std::vector<GpsTime> rt, bt;
    for (const auto& e : *in.rover) rt.push_back(e.time);
    for (const auto& e : *in.base) bt.push_back(e.time);
    matches_ = gnss::match_base_epochs(rt, bt, o.max_base_age_s);
    sd_ = true;
    if (o.carrier) carrier_.emplace(in.nav, in.base, o);
  }
  // Per-epoch buffers sized once for the largest epoch (no reallocation on the per-epoch path).
  size_t max_sats = 0;
  if (in.rover) {
    for (const auto& e : *in.rover) max_sats = std::max(max_sats, e.sats.size());
  }
  re_.sats.reserve(max_sats);
  rows_.reserve(2 * max_sats);
  code_res_by_slot_.resize(o.systems.size());
  for (auto& v : code_res_by_slot_) v.reserve(max_sats);
  doppler_res_.reserve(max_sats);
  active_.reserve(2 * max_sats);
}

Vector3d GnssEpochUpdater::lever_e(const Vector3d& p_e) const {
  const Geodetic llh = geodetic_from_ecef(p_e);
  return R_e_n(llh.lat, llh.lon) * o_.lever_arm_n_m;
}

std::optional<Vector3d> GnssEpochUpdater::lsq_position(size_t rover_index, const Vector3d& p_init,
                                                       bool allow_undifferenced) const {
  if (!in_.nav || !in_.rover) return std::nullopt;
  const gnss::ObsEpoch& re = (*in_.rover)[rover_index];
  const gnss::ObsEpoch* be = nullptr;
  if (sd_) {
    if (matches_[rover_index].base_index >= 0) be = &(*in_.base)[matches_[rover_index].base_index];
    else if (!allow_undifferenced) return std::nullopt;
  }
  gnss::SolverOptions so;
  so.elevation_mask_rad = o_.elevation_mask_rad;
  so.min_cn0_dbhz = o_.min_cn0_dbhz;
  so.weights = o_.weights;
  so.fault_probability = o_.fault_probability;
  gnss::ObsEpoch filtered = re;
  std::erase_if(filtered.sats, [&](const gnss::SatObs& s) { return system_slot(o_.systems, s.sat.system) < 0; });
  if (in_.gnss_mask) in_.gnss_mask(filtered);
  const auto sol = gnss::solve_epoch(*in_.nav, filtered, be, o_.base_position_e.value_or(Vector3d::Zero()), p_init, so);
  if (!sol.ok()) return std::nullopt;
  return sol.p_ea_e;
}

void GnssEpochUpdater::update(ErrorStateFilter& f, size_t gi, GpsTime t_proc, const StrideVelocity& stride,
                              bool& clock_initialized, EngineSummary& sum, int& used_out, int& rejected_out,
                              std::vector<GnssRowRecord>* records) {
  re_ = (*in_.rover)[gi];  // copy into a reused buffer (no allocation once its capacity suffices)
  const bool ant = f.has_antenna();  // antenna states (docs/carrier.md §10)
  gnss::ObsEpoch& re = re_;
  if (in_.gnss_mask) {
    const size_t before = re.sats.size();
    in_.gnss_mask(re);
    if (before > re.sats.size()) count_outcome(sum.gnss_skipped, "masked", before - re.sats.size());
    if (re.sats.empty() && before > 0) {
      ++sum.gnss_epochs_masked;
      return;
    }
  }
  if (carrier_) carrier_->screen_rover(re);
  last_carrier_ = CarrierEpoch{};
  const gnss::ObsEpoch* be = nullptr;
  std::optional<gnss::ObsEpoch> propagated;
  // No base epoch within max_base_age_s (a base that stopped): the epoch is processed undifferenced. The clock states
  // change meaning (rover-base vs rover clock), so they are re-initialized at every switch (docs/robustness.md).
  const bool sd = sd_ && matches_[gi].base_index >= 0;
  if (sd_ && !sd) ++sum.gnss_epochs_undifferenced_no_base;
  if (last_sd_ && *last_sd_ != sd) clock_initialized = false;
  last_sd_ = sd;
  if (sd) {
    be = &(*in_.base)[matches_[gi].base_index];
    // An older (or later) base epoch is moved to the rover epoch with its own Doppler: the base clock drift is in
    // the Doppler, so the differential clock stays continuous across base epochs (docs/fusion.md §3).
    if (std::abs(re.time - be->time) > 1e-3) {
      propagated = gnss::propagate_base_with_doppler(*be, re.time);
      be = &*propagated;
    }
  }
  const int n = f.layout().dim();
  const double lag_s = t_proc - re.time;  // the state is at t_proc; move the antenna back to the epoch
  const Vector3d p_imu = f.x().nav.p_eb_e - f.x().nav.v_eb_e * lag_s;
  // Eq. 14.1: the level-frame arm plus the part fixed in the foot's heading frame, whose heading error enters the
  // code rows through eq. 14.2 (the arm's rotation rate is left out of the Doppler rows: 0.1 m × the foot's yaw
  // rate, inside the stride-velocity σ).
  const Geodetic llh_imu = geodetic_from_ecef(p_imu);
  const LeverArm arm = lever_arm_e(o_.lever_arm_n_m, o_.lever_arm_heading_m, R_e_n(llh_imu.lat, llh_imu.lon),
                                   f.x().nav.R_e_b());
  // Antenna (body) velocity: the foot's stride-average velocity (eq. 13.1) or, with the kFoot model or before a
  // cycle of history exists, the foot's own velocity. With antenna states: the antenna's own (eq. 10.3).
  std::optional<Vector3d> v_stride;
  if (o_.antenna_velocity_model == AntennaVelocityModel::kStrideAverage && !ant) v_stride = stride.velocity_e();
  const Vector3d v_a = ant ? f.antenna_v_e() : v_stride ? *v_stride : f.x().nav.v_eb_e;
  const Vector3d p_a = ant ? Vector3d(f.antenna_p_e() - v_a * lag_s) : Vector3d(p_imu + arm.arm_e);
  const int pos_col = ant ? f.antenna_offset() : ins::kPos.offset;
  const Geodetic llh = geodetic_from_ecef(p_a);
  std::vector<GnssRow>& rows = rows_;
  rows.clear();
  code_sigma_.clear();
  std::vector<std::vector<double>>& code_res_by_slot = code_res_by_slot_;
  code_res_by_slot.resize(o_.systems.size());
  for (auto& v : code_res_by_slot) v.clear();
  for (const gnss::SatObs& so : re.sats) {
    const int slot = system_slot(o_.systems, so.sat.system);
    if (slot < 0) {
      count_outcome(sum.gnss_skipped, "system_not_configured");
      continue;
    }
    if (std::isnan(so.pseudorange_m)) { count_outcome(sum.code_used_rejected, "no_pseudorange"); continue; }
    if (!std::isnan(so.cn0_dbhz) && so.cn0_dbhz < o_.min_cn0_dbhz) { count_outcome(sum.code_used_rejected, "low_cn0"); continue; }
    gnss::SignalAtReceiver rs, bs;
    rs.pseudorange_m = so.pseudorange_m;
    rs.range_rate_mps = -so.wavelength_m * so.doppler_hz;
    auto sr = gnss::satellite_state_at_reception(*in_.nav, so.sat, re.time, so.pseudorange_m);
    if (!sr) { count_outcome(sum.code_used_rejected, "no_ephemeris"); continue; }
    rs.sat = *sr;
    const gnss::ElevationAzimuth ea = gnss::elevation_azimuth(p_a, sr->p_es_e);
    if (ea.elevation < o_.elevation_mask_rad) { count_outcome(sum.code_used_rejected, "below_elevation_mask"); continue; }
    double cn0_b = so.cn0_dbhz;
    gnss::MeasurementRow code, rate;
    double sigma_c = gnss::measurement_sigma(o_.weights, so.cn0_dbhz, ea.elevation, false);
    double sigma_d = gnss::measurement_sigma(o_.weights, so.cn0_dbhz, ea.elevation, true);
    if (so.sat.system == gnss::System::kGlonass) sigma_c *= o_.weights.glonass_code_factor;
    bool have_rate = o_.use_doppler && std::isfinite(rs.range_rate_mps);
    if (sd) {
      auto it = std::find_if(be->sats.begin(), be->sats.end(), [&](const gnss::SatObs& b) { return b.sat == so.sat; });
      if (it == be->sats.end() || std::isnan(it->pseudorange_m)) { count_outcome(sum.code_used_rejected, "not_at_base"); continue; }
      auto sb = gnss::satellite_state_at_reception(*in_.nav, so.sat, be->time, it->pseudorange_m);
      if (!sb) { count_outcome(sum.code_used_rejected, "no_ephemeris"); continue; }
      bs.pseudorange_m = it->pseudorange_m;
      bs.range_rate_mps = -it->wavelength_m * it->doppler_hz;
      bs.sat = *sb;
      cn0_b = it->cn0_dbhz;
      const double el_b = gnss::elevation_azimuth(*o_.base_position_e, sb->p_es_e).elevation;
      const double sb_c = gnss::measurement_sigma(o_.weights, cn0_b, el_b, false) *
                          (so.sat.system == gnss::System::kGlonass ? o_.weights.glonass_code_factor : 1.0);
      sigma_c = std::hypot(sigma_c, sb_c);
      sigma_d = std::hypot(sigma_d, gnss::measurement_sigma(o_.weights, cn0_b, el_b, true));
      code = gnss::sd_pseudorange(so.sat, rs, bs, p_a, *o_.base_position_e, f.clock(slot));
      have_rate = have_rate && std::isfinite(bs.range_rate_mps);
      if (have_rate) rate = gnss::sd_range_rate(so.sat, rs, bs, p_a, v_a, *o_.base_position_e, f.drift());
    } else {
      const double iono = in_.nav->has_klobuchar ? gnss::klobuchar_delay_m(in_.nav->klobuchar, re.time, llh, ea) : 0.0;
      const double tropo = gnss::saastamoinen_delay_m(llh, ea.elevation);
      code = gnss::ud_pseudorange(so.sat, rs, p_a, f.clock(slot), iono, tropo);
      if (have_rate) rate = gnss::ud_range_rate(so.sat, rs, p_a, v_a, f.drift());
    }
    GnssRow rc;
    rc.sat = so.sat;
    rc.residual = code.residual;
    rc.sigma = sigma_c;
    rc.h = ins::ErrorRowVector::Zero(n);
    rc.h.segment<3>(pos_col) = code.J_p;
    if (!ant) rc.h.segment<3>(ins::kAtt.offset) = code.J_p * arm.d_arm_d_phi_e;  // eq. 14.2 (zero without a heading part)
    rc.j_antenna = code.J_p;
    rc.h(f.clock_offset(slot)) = code.J_clock;
    if (f.has_multipath()) {
      // Code multipath σ_mp(C/N0) u_s (docs/consistency.md eq. M.2); SD: rover and base in quadrature.
      auto mp_sigma = [&](double cn0) {
        const double c = std::isnan(cn0) ? o_.multipath_cn0_ref_dbhz : cn0;
        return o_.multipath_sigma_m * std::pow(10.0, std::max(0.0, o_.multipath_cn0_ref_dbhz - c) / 20.0);
      };
      // GLONASS: the factor of its code σ applies to the correlated part too (its FDMA inter-frequency biases are
      // constant per satellite: white, they would average down over a walk and pull the position; eq. M.2a).
      const double glo = so.sat.system == gnss::System::kGlonass ? o_.weights.glonass_code_factor : 1.0;
      const double s_mp = glo * (sd ? std::hypot(mp_sigma(so.cn0_dbhz), mp_sigma(cn0_b)) : mp_sigma(so.cn0_dbhz));
      bool reset = false;
      const int ms = f.multipath_slot(so.sat, re.time.ns(), reset);
      if (reset) ++sum.multipath_resets;
      if (ms >= 0) {
        rc.h(f.multipath_index(ms)) = s_mp;
        rc.residual -= s_mp * f.multipath_value(ms);
      } else {
        rc.sigma = std::hypot(rc.sigma, s_mp);
      }
    }
    code_res_by_slot[slot].push_back(rc.residual);
    if (carrier_) code_sigma_[so.sat] = rc.sigma;
    rows.push_back(rc);
    if (have_rate) {
      GnssRow rd;
      rd.sat = so.sat;
      rd.doppler = true;
      rd.residual = rate.residual;
      rd.sigma = sigma_d;
      rd.h = ins::ErrorRowVector::Zero(n);
      rd.h.segment<3>(pos_col) = rate.J_p;
      rd.j_antenna = rate.J_v;
      if (ant) {
        rd.h.segment<3>(f.antenna_offset() + 3) = rate.J_v;  // eq. 10.3
      } else if (v_stride) {
        // δv̄ = −[v̄×] φ (eq. 13.2): the heading error rotates the INS stride; the velocity error is not in v̄.
        rd.h.segment<3>(ins::kAtt.offset) = rate.J_v * stride_velocity_attitude_jacobian(*v_stride);
      } else {
        rd.h.segment<3>(ins::kVel.offset) = rate.J_v;
      }
      rd.h(f.drift_offset()) = rate.J_drift;
      rows.push_back(rd);
    }
  }
  if (rows.empty()) return;
  // Clock initialization / jump detection from the median code innovation per constellation.
  for (size_t s = 0; s < o_.systems.size(); ++s) {
    if (code_res_by_slot[s].empty()) continue;
    const double med = median(code_res_by_slot[s]);
    const double sd = std::sqrt(f.P()(f.clock_offset(static_cast<int>(s)), f.clock_offset(static_cast<int>(s))));
    if (!clock_initialized || (std::abs(med) > o_.clock_jump_threshold_m && std::abs(med) > 5.0 * sd)) {
      if (clock_initialized) ++sum.clock_resets;
      f.reset_clock(static_cast<int>(s), f.clock(static_cast<int>(s)) + med, 30.0);
      for (GnssRow& r : rows) {
        if (!r.doppler && system_slot(o_.systems, r.sat.system) == static_cast<int>(s)) r.residual -= med;
      }
    }
  }
  if (!clock_initialized) {
    std::vector<double>& d = doppler_res_;
    d.clear();
    for (const GnssRow& r : rows) if (r.doppler) d.push_back(r.residual);
    if (!d.empty()) {
      const double med = median(d);
      f.reset_drift(f.drift() + med, 1.0);
      for (GnssRow& r : rows) if (r.doppler) r.residual -= med;
    }
    clock_initialized = true;
  }
  // Noise: independent per measurement + the non-rigid antenna offset/velocity common to all satellites.
  const Eigen::Matrix3d C_pos = antenna_position_cov_e(o_, p_a);
  const Eigen::Matrix3d C_vel = antenna_velocity_cov_e(o_, p_a, v_stride.has_value());
  // With antenna states the offset is in the state (eq. 10.3): no common term.
  const CommonAntennaNoise noise{ant ? Eigen::Matrix3d::Zero() : C_pos, ant ? Eigen::Matrix3d::Zero() : C_vel};
  std::vector<int>& active = active_;
  int rejected_code = 0;
  bool updated = false;
  if (static_cast<int>(rows.size()) <= kMaxGnssRows) {
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxGnssRows, ins::kMaxErrorDim> H;
    Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, kMaxGnssRows, 1> r;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, kMaxGnssRows, kMaxGnssRows> R;
    faults_.test(rows, n, noise, f.P(), re.time, active, records, sum, rejected_code, H, r, R);
    updated = f.update(r, H, R);
  } else {
    MatrixXd H, R;
    VectorXd r;
    faults_.test(rows, n, noise, f.P(), re.time, active, records, sum, rejected_code, H, r, R);
    updated = f.update(r, H, R);
  }
  if (updated) ++sum.gnss_epochs_used;
  faults_.record_history(rows);
  if (carrier_ && sd && updated) {
    // The phase rows at the state the code and Doppler left (sequential update; docs/carrier.md §8), the antenna
    // moved back to the epoch as above.
    const Vector3d p_imu2 = f.x().nav.p_eb_e - f.x().nav.v_eb_e * lag_s;
    const Geodetic llh2 = geodetic_from_ecef(p_imu2);
    LeverArm arm2 = lever_arm_e(o_.lever_arm_n_m, o_.lever_arm_heading_m, R_e_n(llh2.lat, llh2.lon),
                                f.x().nav.R_e_b());
    Vector3d p_a2 = p_imu2 + arm2.arm_e;
    if (ant) {  // the antenna states carry the offset (eq. 10.3)
      p_a2 = f.antenna_p_e() - f.antenna_v_e() * lag_s;
      arm2 = LeverArm{};
    }
    std::vector<int> clock_slot_of_system(static_cast<int>(gnss::System::kSbas) + 1, -1);
    for (size_t k = 0; k < o_.systems.size(); ++k) clock_slot_of_system[static_cast<int>(o_.systems[k])] = static_cast<int>(k);
    last_carrier_ = carrier_->update(f, re, *be, matches_[gi].base_index, std::abs(matches_[gi].age_s), p_a2, arm2,
                                     ant ? Eigen::Matrix3d::Zero() : C_pos, clock_slot_of_system, code_sigma_, sum,
                                     pos_col);
    last_carrier_time_ = re.time;
  }
  // Divergence watch: most code rows of a well-observed epoch rejected, epoch after epoch (kImplausibleEpochs).
  const int code_rows = static_cast<int>(std::count_if(rows.begin(), rows.end(), [](const GnssRow& w) { return !w.doppler; }));
  if (code_rows >= kImplausibleMinCodeRows && 2 * rejected_code > code_rows) ++implausible_streak_;
  else implausible_streak_ = 0;
  const char* outcome = updated ? "used" : "update_failed";
  int used_code = 0;
  for (int i : active) {
    if (rows[i].doppler) count_outcome(sum.doppler_used_rejected, outcome);
    else { count_outcome(sum.code_used_rejected, outcome); used_code += updated; }
  }
  used_out = used_code;
  rejected_out = rejected_code;
}

}  // namespace pednav::fusion
