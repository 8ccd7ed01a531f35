// SPDX-License-Identifier: BSD-2-Clause
// The forward pass (fusion/forward_runner.hpp).
#include "fusion/forward_runner.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/antenna_state.hpp"
#include "fusion/fault_detection.hpp"
#include "fusion/rts.hpp"
#include "ins/mechanization.hpp"

namespace pednav::fusion {
namespace {

using Eigen::Vector3d;

// ins mode: yaw σ kept inside the filter; the rest of the configured initial heading σ is a frame rotation carried
// outside it (docs/fusion.md §5.5). Small but non-zero so that P stays positive definite from the first epoch.
constexpr double kInsFilterSigmaYawRad = 0.1 * 3.14159265358979323846 / 180.0;
// Re-initialization from a GNSS epoch solution after divergence (tc mode): at most this many per run; the attitude is
// the last healthy stance attitude, its heading may be off (wide σ), the walker's velocity is unknown.
constexpr int kMaxReinitializations = 5;
constexpr double kStatusMaxAge_s = 1.5;
// Antenna states: a GNSS epoch outside a stance ties the antenna when no stance did for this long [s].
constexpr double kAntennaTieMaxGapS = 2.0;  // a GNSS epoch's carrier status holds for this long (docs/carrier.md §6)
constexpr double kReinitSigmaYawRad = 30.0 * 3.14159265358979323846 / 180.0;
constexpr double kReinitSigmaVelMps = 2.0;
constexpr double kReinitSigmaPosM = 10.0;  // an epoch least-squares position (single epoch, possibly undifferenced)
// The restart happens during a stance (foot flat and still: the last stance attitude and zero velocity hold there)
// with a GNSS epoch solution at most this old [s] (the walker moves ~1.5 m/s: well inside kReinitSigmaPosM).
constexpr double kReinitMaxFixAgeS = 2.0;

}  // namespace

ForwardRunner::ForwardRunner(const EngineInputs& in, const EngineOptions& o,
                             const std::vector<ins::ZuptDecision>& decisions)
    : in_(in), o_(o), decisions_(decisions), gnss_(in, o), stance_(o) {
  if (in.imu) {
    // The stance samples a ZUPT may use; the core of a short stance spans one mechanization interval, so that
    // every detected stance keeps at least one update.
    zupt_ok_ = ins::zupt_update_samples(decisions, *in.imu, o.zupt_edge_s, 1.0 / o.mechanization_rate_hz);
    // A stance shorter than the mechanization interval may hold no interval end: its interval then ends at the
    // stance (docs/zupt.md §5), so that every detected stance keeps a ZUPT.
    if (o.zupt_updates) {
      forced_end_ = ins::zupt_forced_interval_ends(decisions, zupt_ok_, *in.imu,
                                                   ins::IncrementIntegrator(ins::IncrementOptions{o.mechanization_rate_hz}).period_ns());
    }
  }
  if (o.repair_saturation && in.imu) {
    ins::SaturationOptions so;
    so.gyro_range_radps = o.spec.gyro_range;
    so.accel_range_mps2 = o.spec.accel_range;
    saturation_ = ins::repair_saturation(*in.imu, so);
  }
}

Expected<void> ForwardRunner::run(size_t start, const ins::NavState& nav0, const ins::ImuErrors& imu0,
                                  const PassOptions& po, EngineResult& result) {
  const auto& samples = *in_.imu;
  ErrorStateFilter f(o_, static_cast<int>(o_.systems.size()));
  if (!f.problem().empty()) return make_error(f.problem());
  // ins mode: an initial heading error only rotates the whole trajectory about the start point — no ZUPT or ZARU
  // observes it (H_D s = 0 for the rotation direction s, docs/fusion.md §5.5). Its variance is carried outside the
  // filter and added to the reported covariance; inside, a large yaw variance would only turn ZUPT model errors
  // (residual foot motion at stance onset) into heading jumps.
  frame_ = FrameYaw{};
  double filter_sigma_yaw_rad = o_.initial_sigma_yaw_rad;
  if (o_.mode == Mode::kInsOnly && o_.ins_heading_as_frame && filter_sigma_yaw_rad > kInsFilterSigmaYawRad) {
    frame_.var_rad2 = filter_sigma_yaw_rad * filter_sigma_yaw_rad - kInsFilterSigmaYawRad * kInsFilterSigmaYawRad;
    frame_.origin_e = nav0.p_eb_e;
    frame_.up_e = R_e_n(geodetic_from_ecef(nav0.p_eb_e).lat, geodetic_from_ecef(nav0.p_eb_e).lon).col(2) * -1.0;
    filter_sigma_yaw_rad = kInsFilterSigmaYawRad;
  }
  f.init(nav0, imu0, filter_sigma_yaw_rad);
  stride_.reset();
  init_antenna_from_foot(f, o_, stride_);  // antenna states (docs/carrier.md §10): at the foot + arm
  EngineSummary& sum = result.summary;
  if (o_.mode == Mode::kTightlyCoupled) {
    // The outcomes every epoch can have exist from the start (0 until they happen): a first rejection later in
    // the run then does not allocate a map node on the per-epoch path (tests/fusion/test_allocations.cpp).
    for (auto* m : {&sum.code_used_rejected, &sum.doppler_used_rejected}) {
      m->try_emplace("used", 0);
      m->try_emplace("innovation_fault", 0);
    }
    sum.code_used_rejected.try_emplace("persistent_fault", 0);
    gnss_.reserve_fault_history();
  }
  // Smoother (docs/fusion.md §12): one backward record per output epoch, carried forward from each output epoch
  // to the next by the filter (eqs. 12.14-12.20).
  // Consider states (the g-sensitivity, docs/error_state.md §5) leave the forward error with a non-zero conditional
  // mean: the smoother then runs on the Kalman-gain filter of the same linearization (§12.6).
  const bool smooth = o_.smoother_enabled;
  const int n_state = f.layout().dim();
  RtsSegment segment;
  RtsStore segments(n_state);
  std::vector<ins::InsState> nominal_at_output;
  std::vector<std::array<Vector3d, 2>> antenna_at_output;  // antenna states: nominal position, velocity
  // Storage sized once from the data span (no reallocation on the per-epoch path; docs/performance.md).
  const double span_s = std::max(0.0, in_.imu->back().t - nav0.t);
  const size_t expected_outputs = static_cast<size_t>(span_s * o_.output_rate_hz) + 2;
  result.epochs.reserve(result.epochs.size() + expected_outputs);
  if (smooth) {
    segments.reserve(expected_outputs);
    nominal_at_output.reserve(expected_outputs);
    if (f.has_antenna()) antenna_at_output.reserve(expected_outputs);
  }
  if (o_.record_gnss_rows && in_.rover) result.gnss_rows.reserve(result.gnss_rows.size() + in_.rover->size() * gnss_.row_capacity());
  bool segment_open = false;
  ins::IncrementOptions io;
  io.rate_hz = o_.mechanization_rate_hz;
  ins::IncrementIntegrator integrator(io);
  const int64_t out_period_ns = static_cast<int64_t>(std::llround(1e9 / o_.output_rate_hz));
  int64_t next_out_ns = ((nav0.t.ns() + out_period_ns - 1) / out_period_ns) * out_period_ns;
  size_t gi = 0;
  bool clock_initialized = false;
  const bool gnss_pass = po.gnss && o_.mode == Mode::kTightlyCoupled && in_.rover;
  if (in_.rover) {
    while (gi < in_.rover->size() && (*in_.rover)[gi].time < nav0.t) {
      if (gnss_pass) count_outcome(sum.gnss_skipped, "outside_imu_span", (*in_.rover)[gi].sats.size());
      ++gi;
      ++sum.gnss_epochs_before_start;
    }
  }
  size_t sample_index = start;
  int last_used = 0, last_rejected = 0;
  bool failed = false;
  int64_t last_covariance_check_ns = std::numeric_limits<int64_t>::min() / 2;
  bool prev_zupt = false;  // a ZUPT at the previous mechanization epoch (ZARU: the whole interval is stance)
  std::optional<StepTracker> steps;  // seed 000 step-velocity aiding (fusion/step_velocity.hpp)
  if (o_.step_velocity.enabled) steps.emplace(o_.step_velocity);
  std::string fail_message;
  // Recovery (docs/robustness.md): after a failed health check in tc mode the filter waits for the next GNSS epoch
  // that the epoch least squares solves and re-initializes there. The smoother cannot cross a re-initialization.
  const bool can_reinit = gnss_pass && in_.nav;
  bool waiting = false;
  std::optional<PendingFix> pending;  // the latest solvable GNSS epoch while waiting
  std::optional<GpsTime> reinitialized_at;
  ins::InsState last_stance = f.x();  // attitude and IMU errors to restart from
  gnss_.restart(/*clear_fault_history=*/false);

  int64_t next_nhc_ns = 0;
  // Antenna states (docs/carrier.md §10): the tie at mid-stance, and at a GNSS epoch when no stance tied the antenna
  // for kAntennaTieMaxGapS (a hand-held IMU, a long swing).
  const std::vector<size_t> tie_samples =
      f.has_antenna() ? antenna_tie_samples(decisions_, samples) : std::vector<size_t>{};
  size_t next_tie = static_cast<size_t>(std::lower_bound(tie_samples.begin(), tie_samples.end(), start) - tie_samples.begin());
  int64_t last_tie_ns = std::numeric_limits<int64_t>::min() / 2;
  auto on_increment = [&](const ins::ImuIncrement& inc) {
    if (failed || waiting) return;
    const Vector3d p_before = f.x().nav.p_eb_e;
    f.predict(inc);
    ++sum.mechanization_steps;
    // ZUPT (+ ZARU) when the detector flags the sample at the interval end as stance, away from the stance's
    // edges (zupt_edge_s, docs/zupt.md §5).
    const bool stance = decisions_[std::min(sample_index, decisions_.size() - 1)].stance;
    stride_.push(inc.t1.ns(), f.x().nav.p_eb_e - p_before, stance);  // mechanized displacement only (eq. 13.1)
    const bool zupt_now = stance && zupt_ok_[std::min(sample_index, zupt_ok_.size() - 1)];
    if (zupt_now && o_.zupt_updates) {
      stance_.zupt_update(f, inc, prev_zupt, sum);
      ++sum.zupt_updates;
    }
    if (steps) {
      if (auto m = steps->push(f.x().nav, inc.dt_s, stance)) stance_.step_velocity_update(f, *m, sum);
    }
    if (next_tie < tie_samples.size() && tie_samples[next_tie] <= sample_index) {
      while (next_tie < tie_samples.size() && tie_samples[next_tie] <= sample_index) ++next_tie;
      if (antenna_tie_update(f, o_, stride_, /*mid_stance=*/true, sum)) last_tie_ns = inc.t1.ns();
    }
    // GNSS epochs up to the interval end.
    while (po.gnss && o_.mode == Mode::kTightlyCoupled && in_.rover && gi < in_.rover->size() && (*in_.rover)[gi].time <= inc.t1) {
      if (f.has_antenna() && !stance && inc.t1.ns() - last_tie_ns > static_cast<int64_t>(kAntennaTieMaxGapS * 1e9)) {
        if (antenna_tie_update(f, o_, stride_, /*mid_stance=*/false, sum)) last_tie_ns = inc.t1.ns();
      }
      gnss_.update(f, gi, inc.t1, stride_, clock_initialized, sum, last_used, last_rejected,
                  o_.record_gnss_rows ? &result.gnss_rows : nullptr);
      ++gi;
    }
    if (po.hand_nhc_interval_s > 0.0 && inc.t1.ns() >= next_nhc_ns) {
      StanceUpdater::hand_nhc_update(f, kHandNhcSigmaCrossMps, kHandNhcSigmaUpMps);
      next_nhc_ns = inc.t1.ns() + std::llround(po.hand_nhc_interval_s * 1e9);
    }
    prev_zupt = zupt_now;
    std::string why;
    const bool output_now = inc.t1.ns() >= next_out_ns;
    // The symmetry / PSD test (an LDLT) at output epochs, at most once per second (outputs at the mechanization
    // rate, as in the heading pass, would otherwise pay it every step); finiteness and variances every step.
    const bool check_covariance = output_now && inc.t1.ns() - last_covariance_check_ns >= kNsPerS;
    if (check_covariance) last_covariance_check_ns = inc.t1.ns();
    if (!f.healthy(why, check_covariance) || gnss_.implausible_streak() >= kImplausibleEpochs) {
      if (why.empty()) {
        why = "innovations implausible: " + std::to_string(gnss_.implausible_streak()) +
              " consecutive GNSS epochs with most code measurements rejected";
      }
      const std::string event = "filter diverged at " + inc.t1.to_string() + ": " + why;
      sum.covariance_healthy = false;
      sum.health_message = event;
      sum.health_events.push_back(event);
      if (can_reinit && sum.reinitializations < kMaxReinitializations) {
        waiting = true;
        return;
      }
      failed = true;
      fail_message = event;
      if (can_reinit) fail_message += " (after " + std::to_string(kMaxReinitializations) + " re-initializations)";
      return;
    }
    if (stance) last_stance = f.x();
    if (output_now) {
      while (next_out_ns <= inc.t1.ns()) next_out_ns += out_period_ns;
      result.epochs.push_back(output(f.x(), f.P(), inc.t1, stance, last_used, last_rejected));
      if (f.has_antenna()) antenna_output(result.epochs.back(), f.antenna_p_e(), f.antenna_v_e(), f.P(), f.antenna_offset());
      if (o_.carrier) {
        // The status of the last GNSS epoch while it is recent (docs/carrier.md §6), else the INS carries it.
        EpochOutput& e = result.epochs.back();
        const CarrierEpoch& c = gnss_.last_carrier();
        const bool recent = inc.t1 - gnss_.last_carrier_time() <= kStatusMaxAge_s;
        e.solution_status = static_cast<int>(!recent ? SolutionStatus::kIns
                                             : c.status ? static_cast<SolutionStatus>(c.status) : SolutionStatus::kCode);
        e.n_fixed_ambiguities = recent ? c.n_fixed : 0;
        e.ar_ratio = recent ? c.ratio : 0.0;
      }
      last_used = last_rejected = 0;
      if (smooth && !reinitialized_at) {
        if (segment_open) {
          f.smoother_close(segment);
          segments.push(segment);
        }
        f.smoother_restart();
        segment_open = true;
        nominal_at_output.push_back(f.x());
        if (f.has_antenna()) antenna_at_output.push_back({f.antenna_p_e(), f.antenna_v_e()});
      }
    }
    if (in_.on_step) in_.on_step(inc.t1);
  };

  const Vector3d up_start_e = nav0.p_eb_e.normalized();
  Vector3d p_last_e = nav0.p_eb_e;
  double walked_m = 0.0, milestone_m = po.walked_milestone_m;
  auto stop_walking = [&] {
    const Vector3d d = f.x().nav.p_eb_e - p_last_e;
    p_last_e = f.x().nav.p_eb_e;
    if (!decisions_[std::min(sample_index, decisions_.size() - 1)].stance) {
      walked_m += (d - d.dot(up_start_e) * up_start_e).norm();
    }
    if (walked_m < milestone_m) return false;
    const double reached = milestone_m;
    milestone_m *= 2.0;
    return po.at_milestone(result, reached);
  };
  // Saturated samples (docs/ins.md §9): the repaired copies replace them; each run's σ goes into the filter
  // with the run's last sample.
  const auto& sat_samples = saturation_.samples;
  const auto& sat_runs = saturation_.runs;
  size_t sat_sample = 0, sat_run = 0;
  for (const auto& r : sat_runs) {
    if (r.last < start) continue;
    ++sum.saturated_runs;
    if (r.reconstructed) ++sum.saturated_runs_reconstructed;
    if (r.gyro) sum.saturation_max_added_deg = std::max(sum.saturation_max_added_deg, std::abs(r.added) * kRadToDeg);
  }
  for (const auto& s : sat_samples) sum.saturated_samples += s.index >= start ? 1 : 0;
  sum.saturation_notes = saturation_.notes;
  ins::ImuSample repaired;
  for (; sample_index < samples.size(); ++sample_index) {
    const ins::ImuSample* raw_ptr = &samples[sample_index];
    while (sat_sample < sat_samples.size() && sat_samples[sat_sample].index < sample_index) ++sat_sample;
    if (sat_sample < sat_samples.size() && sat_samples[sat_sample].index == sample_index) {
      repaired.t = raw_ptr->t;
      repaired.omega_ib_b = sat_samples[sat_sample].omega_ib_b;
      repaired.f_ib_b = sat_samples[sat_sample].f_ib_b;
      raw_ptr = &repaired;
    }
    while (sat_run < sat_runs.size() && sat_runs[sat_run].last < sample_index) ++sat_run;
    const ins::ImuSample& raw = *raw_ptr;
    if (in_.cancel && (sample_index - start) % kCancelCheckSamples == 0 && in_.cancel(raw.t)) {
      return make_error(kCancelledMessage);
    }
    if (po.stop && raw.t > *po.stop) break;
    if (po.at_milestone && milestone_m > 0.0 && stop_walking()) break;
    if (!raw.omega_ib_b.allFinite() || !raw.f_ib_b.allFinite()) {
      count_outcome(sum.imu_rejected, "non_finite");
      continue;
    }
    if (waiting) {
      const bool stance_now = decisions_[std::min(sample_index, decisions_.size() - 1)].stance;
      if (!reinitialize(f, raw.t, stance_now, gi, last_stance, pending, sum)) {
        count_outcome(sum.imu_skipped, "filter_diverged");
        continue;
      }
      waiting = false;
      reinitialized_at = raw.t;
      f.smoother_stop();
      integrator = ins::IncrementIntegrator(io);  // the increments restart at this sample
      clock_initialized = false;
      gnss_.restart(/*clear_fault_history=*/true);  // the diverged filter's innovations are no evidence
      prev_zupt = false;
      last_used = last_rejected = 0;
      stride_.reset();
      if (steps) steps.emplace(o_.step_velocity);
    }
    ++sum.imu_samples;
    for (; sat_run < sat_runs.size() && sat_runs[sat_run].last == sample_index; ++sat_run) {
      const auto& r = sat_runs[sat_run];
      f.add_saturation_noise(r.gyro, r.axis, r.sigma * r.sigma);
    }
    const ins::ImuSample corrected = ins::correct_sample(raw, f.x().imu);
    integrator.push(corrected, on_increment);
    if (failed) break;
    if (sample_index < forced_end_.size() && forced_end_[sample_index]) {
      ins::ImuIncrement early;
      if (integrator.cut(early)) {
        ++sum.zupt_short_stance_interval_ends;
        on_increment(early);
      }
      if (failed) break;
    }
  }
  // The data ended inside a mechanization interval: that partial interval (up to the last sample) is one more step,
  // so the solution reaches the last sample (without it the last up to 1/rate s of every log were dropped).
  if (sample_index == samples.size() && !failed && !waiting) {
    ins::ImuIncrement last;
    if (integrator.flush(last)) on_increment(last);
  }
  if (pending) count_outcome(sum.gnss_skipped, "filter_diverged", pending->n_sats);
  sum.imu_estimate = f.imu_estimate();
  if (gnss_pass) {
    sum.gnss_epochs_before_start += static_cast<long>(in_.rover->size() - gi);
    for (size_t g = gi; g < in_.rover->size(); ++g) {
      count_outcome(sum.gnss_skipped, waiting ? "filter_diverged" : "outside_imu_span", (*in_.rover)[g].sats.size());
    }
  }
  if (waiting && !failed) {
    failed = true;
    fail_message = sum.health_message + "; no later GNSS epoch could be solved to re-initialize";
  }
  if (reinitialized_at && smooth) {
    sum.smoother_message = "not smoothed: the filter was re-initialized at " + reinitialized_at->to_string() +
                           " (the backward pass cannot cross a re-initialization)";
  }
  if (failed) {
    sum.covariance_healthy = false;
    sum.health_message = fail_message;
    return make_error(fail_message);
  }
  if (smooth && !reinitialized_at && !result.epochs.empty()) {
    // The tail: the last output epoch -> the last step (eq. 12.10).
    RtsSegment tail;
    f.smoother_close(tail);
    const size_t bytes = segments.bytes() + nominal_at_output.size() * sizeof(ins::InsState) +
                         antenna_at_output.size() * sizeof(antenna_at_output[0]);
    result.smoothed.resize(result.epochs.size());
    bool finite = true;
    size_t bad = 0;
    rts_backward(segments, tail, f.smoother_P(), f.smoother_mean(), [&](size_t k, const ErrorVector& dx,
                                                                         const ErrorMatrix& P) {
      // Smoothed state = forward nominal ⊞ smoothed error (eq. 12.12).
      const ins::InsState xs = ins::boxplus(nominal_at_output[k], dx, f.layout());
      const EpochOutput& fwd = result.epochs[k];
      result.smoothed[k] = output(xs, P, fwd.t, fwd.zupt, fwd.n_sats_used, fwd.n_sats_rejected);
      result.smoothed[k].solution_status = fwd.solution_status;  // smoothed epochs carry the forward status
      result.smoothed[k].n_fixed_ambiguities = fwd.n_fixed_ambiguities;
      result.smoothed[k].ar_ratio = fwd.ar_ratio;
      if (f.has_antenna()) {
        const int a = f.antenna_offset();
        antenna_output(result.smoothed[k], antenna_at_output[k][0] + dx.segment<3>(a),
                       antenna_at_output[k][1] + dx.segment<3>(a + 3), P, a);
      }
      if (finite && (!xs.nav.p_eb_e.allFinite() || !P.allFinite())) {
        finite = false;
        bad = k;
      }
    });
    if (!finite) {
      // The forward solution stands; the smoothed one is withheld and the reason reported.
      sum.smoother_message =
          "smoother diverged at " + result.epochs[bad].t.to_string() + ": non-finite smoothed state or covariance";
      result.smoothed.clear();
      return {};
    }
    sum.smoothed = true;
    sum.smoother_records = static_cast<long>(segments.size() + 1);
    sum.smoother_bytes = static_cast<long>(bytes);
  }
  return {};
}

bool ForwardRunner::reinitialize(ErrorStateFilter& f, GpsTime t, bool stance, size_t& gi, const ins::InsState& last_stance,
                  std::optional<PendingFix>& pending, EngineSummary& sum) {
  while (gi < in_.rover->size() && (*in_.rover)[gi].time <= t) {
    const size_t n_sats = (*in_.rover)[gi].sats.size();
    const Vector3d p_guess = pending ? pending->p_ea_e : last_stance.nav.p_eb_e + gnss_.lever_e(last_stance.nav.p_eb_e);
    const std::optional<Vector3d> pa = gnss_.lsq_position(gi, p_guess, /*allow_undifferenced=*/true);
    if (!pa) {
      count_outcome(sum.gnss_skipped, "filter_diverged", n_sats);
    } else {
      if (pending) count_outcome(sum.gnss_skipped, "filter_diverged", pending->n_sats);
      pending = PendingFix{(*in_.rover)[gi].time, *pa, n_sats};
    }
    ++gi;
  }
  if (!pending || !stance) return false;
  if (t - pending->t > kReinitMaxFixAgeS) {
    count_outcome(sum.gnss_skipped, "filter_diverged", pending->n_sats);
    pending.reset();
    return false;
  }
  count_outcome(sum.gnss_skipped, "reinitialization_epoch", pending->n_sats);
  ins::NavState nav = last_stance.nav;
  nav.t = t;
  nav.p_eb_e = pending->p_ea_e - gnss_.lever_e(pending->p_ea_e);
  nav.v_eb_e.setZero();
  f.init(nav, last_stance.imu, std::max(o_.initial_sigma_yaw_rad, kReinitSigmaYawRad));
  f.set_block_sigma(ins::kVel, kReinitSigmaVelMps);
  f.set_block_sigma(ins::kPos, std::max(o_.initial_sigma_pos_m, kReinitSigmaPosM));
  stride_.reset();
  init_antenna_from_foot(f, o_, stride_);
  ++sum.reinitializations;
  sum.health_events.push_back("re-initialized at " + t.to_string() + " from the GNSS epoch solution of " +
                              pending->t.to_string());
  pending.reset();
  return true;
}

void ForwardRunner::antenna_output(EpochOutput& e, const Vector3d& p_e, const Vector3d& v_e, const ErrorMatrix& P,
                                   int offset) {
  e.has_antenna = true;
  e.ant_p_e = p_e;
  e.ant_v_e = v_e;
  const Geodetic llh = geodetic_from_ecef(p_e);
  const Eigen::Matrix3d Rne = R_e_n(llh.lat, llh.lon).transpose();
  e.cov_ant_p_n = Rne * P.block<3, 3>(offset, offset) * Rne.transpose();
}

EpochOutput ForwardRunner::output(const ins::InsState& x, const ErrorMatrix& P, GpsTime t, bool zupt, int used, int rejected) const {
  EpochOutput e;
  e.t = t;
  e.nav = x.nav;
  e.imu = x.imu;
  const ins::NavState& nav = x.nav;
  const Geodetic llh = geodetic_from_ecef(e.nav.p_eb_e);
  const Eigen::Matrix3d Rne = R_e_n(llh.lat, llh.lon).transpose();
  Eigen::Matrix3d cov_p_e = P.block<3, 3>(ins::kPos.offset, ins::kPos.offset);
  Eigen::Matrix3d cov_v_e = P.block<3, 3>(ins::kVel.offset, ins::kVel.offset);
  Eigen::Matrix3d cov_att_e = P.block<3, 3>(ins::kAtt.offset, ins::kAtt.offset);
  if (frame_.var_rad2 > 0.0) {
    // Rotation of the trajectory by δψ about the vertical through the start (docs/fusion.md eq. 5.10).
    const Vector3d s_p = frame_.up_e.cross(nav.p_eb_e - frame_.origin_e);
    const Vector3d s_v = frame_.up_e.cross(nav.v_eb_e);
    cov_p_e += frame_.var_rad2 * s_p * s_p.transpose();
    cov_v_e += frame_.var_rad2 * s_v * s_v.transpose();
    cov_att_e += frame_.var_rad2 * frame_.up_e * frame_.up_e.transpose();
  }
  e.cov_p_n = Rne * cov_p_e * Rne.transpose();
  e.cov_v_n = Rne * cov_v_e * Rne.transpose();
  const Eigen::Matrix3d att_n = Rne * cov_att_e * Rne.transpose();
  e.sd_yaw_rad = std::sqrt(std::max(0.0, att_n(2, 2)));
  e.n_sats_used = used;
  e.n_sats_rejected = rejected;
  e.zupt = zupt;
  return e;
}
}  // namespace pednav::fusion
