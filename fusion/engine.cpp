// SPDX-License-Identifier: BSD-2-Clause
// The engine's entry point (fusion/engine.hpp): checks the inputs, runs the stance detector, initializes (the first
// still period levels the IMU and may give the gyro bias; position from the configuration or the first GNSS epoch
// solution; heading from the configuration, the magnetometer or motion) and runs the forward pass with the smoother. The parts:
// fusion/error_state_filter (state, covariance), fusion/gnss_update and fusion/fault_detection (GNSS rows, w-test),
// fusion/stance_updates (ZUPT, ZARU, step velocity), fusion/initialization, fusion/forward_runner (the pass).
#include "fusion/engine.hpp"

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/forward_runner.hpp"
#include "fusion/initialization.hpp"
#include "ins/alignment.hpp"

namespace pednav::fusion {

using Eigen::Vector3d;

namespace {

// A foot's swing turns it faster than this (foot: 3-15 rad/s; ins::CalibrationOptions::swing_rate_radps) for about a
// third of every stride; an IMU above it on fewer than kNotOnFootMaxSwingShare of the samples after its levelling
// window (a hand turning with the walker at a corner), on a GNSS track that moves at least kNotOnFootMinTrackM, is
// not on a foot.
constexpr double kFootSwingRateRadps = 2.0;
constexpr double kNotOnFootMaxSwingShare = 0.005;
// ... and the IMU itself walks: |f| scatters by more than kWalkingAccelStdMps2 (the step's bob and impact; a hand
// ±2-3 m/s², a foot or pocket more) in at least kWalkingWindowShare of the 1-s windows after the levelling window,
// so that a foot IMU at rest under a GNSS track that wanders (multipath, blunders) keeps its ZUPTs.
constexpr double kWalkingAccelStdMps2 = 0.5;
constexpr double kWalkingWindowShare = 0.3;

// Share of the 1-s windows of samples [begin, end) whose |f| has a standard deviation above kWalkingAccelStdMps2.
double walking_window_share(const std::vector<ins::ImuSample>& samples, size_t begin) {
  int windows = 0, walking = 0;
  size_t i = begin;
  while (i < samples.size()) {
    double sum = 0.0, sum2 = 0.0;
    size_t n = 0;
    const GpsTime t0 = samples[i].t;
    for (; i < samples.size() && samples[i].t - t0 < 1.0; ++i, ++n) {
      const double f = samples[i].f_ib_b.norm();
      sum += f;
      sum2 += f * f;
    }
    if (n < 2) continue;
    const double mean = sum / static_cast<double>(n);
    const double var = std::max(0.0, sum2 / static_cast<double>(n) - mean * mean);
    ++windows;
    walking += std::sqrt(var) > kWalkingAccelStdMps2;
  }
  return windows > 0 ? static_cast<double>(walking) / windows : 0.0;
}
constexpr double kNotOnFootMinTrackM = 20.0;
// A hand-held walker who stands (docs/fusion.md eq. 8.5): over 1.5 s (three 0.5-s blocks) |f| scatters by less than
// kHandStandAccelStdMps2 — a walking hand bobs by 1.5-1.8 m/s² (standard deviation over 2 s on the simulated hand; a
// standing hand's tremor is centimetres per second squared) — and the mean rate is below kHandStandRateRadps (a hand
// turning the device at rest gets no ZUPT and ZARU).
constexpr double kHandStandAccelStdMps2 = 0.25;
constexpr double kHandStandRateRadps = 0.05;
constexpr double kHandStandBlockS = 0.5;

// Stance decisions of a hand-held IMU from sample `begin` on: standing (eq. 8.5) or not.
void hand_standing_decisions(const std::vector<ins::ImuSample>& samples, size_t begin,
                             std::vector<ins::ZuptDecision>& decisions) {
  struct Block {
    size_t b = 0, e = 0;
    double sum_f = 0.0, sum_f2 = 0.0;
    Vector3d sum_w = Vector3d::Zero();
  };
  std::vector<Block> blocks;
  for (size_t i = begin; i < samples.size();) {
    Block k;
    k.b = i;
    const GpsTime t0 = samples[i].t;
    for (; i < samples.size() && samples[i].t - t0 < kHandStandBlockS; ++i) {
      const double f = samples[i].f_ib_b.norm();
      k.sum_f += f;
      k.sum_f2 += f * f;
      k.sum_w += samples[i].omega_ib_b;
    }
    k.e = i;
    blocks.push_back(k);
  }
  for (size_t j = 0; j < blocks.size(); ++j) {
    Block w;  // the block and its neighbours
    for (size_t m = j > 0 ? j - 1 : 0; m <= std::min(j + 1, blocks.size() - 1); ++m) {
      w.sum_f += blocks[m].sum_f, w.sum_f2 += blocks[m].sum_f2, w.sum_w += blocks[m].sum_w;
      w.e += blocks[m].e - blocks[m].b;
    }
    const double n = static_cast<double>(w.e);
    const double mean = w.sum_f / n;
    const double sd = std::sqrt(std::max(0.0, w.sum_f2 / n - mean * mean));
    const bool standing = n >= 3 && sd < kHandStandAccelStdMps2 && (w.sum_w / n).norm() < kHandStandRateRadps;
    for (size_t i = blocks[j].b; i < blocks[j].e && i < decisions.size(); ++i) decisions[i].stance = standing;
  }
}

// Largest horizontal distance of the GNSS epoch solutions (every 10th epoch from t_start) from the first one [m];
// 0 without GNSS.
double gnss_track_extent(const EngineInputs& in, const EngineOptions& o, GpsTime t_start) {
  if (!in.rover || !in.nav) return 0.0;
  const GnssEpochUpdater gnss(in, o);
  std::optional<Vector3d> first;
  Vector3d prev = o.base_position_e.value_or(Vector3d::Zero());
  double extent = 0.0;
  for (size_t g = 0; g < in.rover->size(); g += 10) {
    if ((*in.rover)[g].time < t_start) continue;
    const auto pa = gnss.lsq_position(g, prev);
    if (!pa) continue;
    prev = *pa;
    if (!first) first = *pa;
    extent = std::max(extent, enu_from_ecef(*pa, *first).head<2>().norm());
  }
  return extent;
}

}  // namespace

std::vector<std::string> EngineOptions::problems() const {
  std::vector<std::string> p = zupt.problems();
  if (!(mechanization_rate_hz > 0)) p.push_back("mechanization_rate_hz must be > 0");
  if (!(output_rate_hz > 0)) p.push_back("output.rate_hz must be > 0");
  if (!(zupt_sigma_mps > 0)) p.push_back("zupt.sigma_mps must be > 0");
  if (!(fault_probability > 0.5 && fault_probability < 1.0)) p.push_back("fault_rejection.probability must be in (0.5, 1)");
  if (fault_window_epochs < 0 || fault_window_epochs > kMaxFaultWindowEpochs)
    p.push_back("fault_rejection.window_epochs must be in [0, " + std::to_string(kMaxFaultWindowEpochs) + "]");
  if (!(zaru_gate_probability == 0.0 || (zaru_gate_probability > 0.5 && zaru_gate_probability < 1.0)))
    p.push_back("zupt.zaru_gate_probability must be 0 (no gate) or in (0.5, 1)");
  for (const auto& s : spec.problems()) p.push_back("imu.spec: " + s);
  return p;
}

Expected<EngineResult> run_forward(const EngineInputs& in, const EngineOptions& o) {
  if (auto p = o.problems(); !p.empty()) {
    std::string s;
    for (const auto& x : p) s += (s.empty() ? "" : "; ") + x;
    return make_error("engine options: " + s);
  }
  if (!in.imu || in.imu->size() < 10) return make_error("IMU: fewer than 10 samples");
  const auto& samples = *in.imu;
  const bool tc = o.mode == Mode::kTightlyCoupled;
  if (tc) {
    if (!in.nav || !in.rover || in.rover->empty()) return make_error("tc mode needs rover observations and nav data");
    const GpsTime g0 = in.rover->front().time, g1 = in.rover->back().time;
    if (g1 < samples.front().t || g0 > samples.back().t) {
      return make_error("GNSS (" + g0.to_string() + " .. " + g1.to_string() + ") and IMU (" +
                        samples.front().t.to_string() + " .. " + samples.back().t.to_string() +
                        ") time spans do not overlap");
    }
    if (in.base && !o.base_position_e) return make_error("base observations given without a base position");
  }
  if (auto p = ins::stance_label_problem(o.zupt, in.stance_labels, samples.size()); !p.empty()) return make_error(p);
  std::vector<ins::ZuptDecision> decisions = ins::detect_stance(samples, o.zupt, in.stance_labels);

  // Start at the first still period (levelling window): the first stance run of >= kMinLevellingWindowS.
  const auto still_period = first_still_period(samples, decisions);
  if (!still_period) return make_error("IMU: no still period found to level the IMU (the ZUPT detector never fired)");
  const auto [s0, s1] = *still_period;
  EngineOptions opt = o;
  std::string not_on_foot;
  if (tc) {
    // An IMU that is not on a foot (docs/fusion.md §8.2): no swing while the GNSS track moves. A hand moving at a
    // steady speed looks still to every stance detector, so its "stances" would be false ZUPTs: none after the
    // levelling window, and the Doppler rows see the IMU's own velocity.
    size_t swings = 0;
    for (size_t i = s1; i < samples.size(); ++i) swings += samples[i].omega_ib_b.norm() > kFootSwingRateRadps;
    if (static_cast<double>(swings) < kNotOnFootMaxSwingShare * static_cast<double>(samples.size() - s1) &&
        walking_window_share(samples, s1) >= kWalkingWindowShare) {
      const double moved_m = gnss_track_extent(in, o, samples[s0].t);
      if (moved_m >= kNotOnFootMinTrackM) {
        hand_standing_decisions(samples, s1, decisions);  // ZUPTs only while the walker stands (eq. 8.5)
        opt.antenna_velocity_model = AntennaVelocityModel::kFoot;
        not_on_foot = fmt::format("; rates above {:.0f} rad/s on {:.2f} % of the samples (a foot: about a third) while "
                                  "the GNSS track moves {:.0f} m: an IMU not on a foot (hand-held, pocket, body-worn), "
                                  "ZUPTs only while the walker stands",
                                  kFootSwingRateRadps,
                                  100.0 * static_cast<double>(swings) / static_cast<double>(samples.size() - s1),
                                  moved_m);
      }
    }
  }
  const std::vector<ins::ImuSample> still(samples.begin() + static_cast<long>(s0), samples.begin() + static_cast<long>(s1));

  EngineResult result;
  EngineSummary& sum = result.summary;
  for (const auto& d : decisions) sum.zupt_samples += d.stance;
  if (in.rover) sum.gnss_epochs = static_cast<long>(in.rover->size());
  if (in.rover && tc) {
    for (const auto& e : *in.rover) sum.gnss_measurements += static_cast<long>(e.sats.size());
  }
  ForwardRunner runner(in, o, decisions);
  const GnssEpochUpdater& gnss = runner.gnss();

  // Initial position: configured, else the first epoch LSQ solution after the start (antenna -> IMU).
  Vector3d p0;
  std::string how;
  if (o.initial_position_e) {
    p0 = *o.initial_position_e;
    how = "position from configuration";
  } else if (tc) {
    std::optional<Vector3d> pa;
    for (size_t g = 0; g < in.rover->size() && !pa; ++g) {
      if ((*in.rover)[g].time < samples[s0].t) continue;
      pa = gnss.lsq_position(g, o.base_position_e.value_or(Vector3d::Zero()));
      if (pa) how = "position from the GNSS epoch solution at " + (*in.rover)[g].time.to_string();
    }
    if (!pa) return make_error("no GNSS epoch after the IMU start could be solved to initialize the position");
    p0 = *pa - gnss.lever_e(*pa);
  } else {
    return make_error("mode ins needs an initial position (initial.position_ecef_m or initial.lat_deg/lon_deg/h_m)");
  }
  auto level = ins::coarse_level(still, p0, 0.0, kLevellingSanity);
  if (!level) return make_error("IMU levelling at " + samples[s0].t.to_string() + ": " + level.error().message);
  const ins::ImuErrors imu0 = initial_imu_errors(*level, o.spec, sum, how);

  how += not_on_foot;
  // Heading: configured, else from motion (INS/ZUPT track with yaw 0 fitted to the GNSS epoch solutions).
  double yaw0 = 0.0;
  if (o.heading_from_magnetometer) {
    if (!in.mag_b || in.mag_b->size() != samples.size()) {
      return make_error("heading from the magnetometer needs one magnetometer vector per IMU sample (got " +
                        std::to_string(in.mag_b ? in.mag_b->size() : 0) + " for " + std::to_string(samples.size()) +
                        " samples)");
    }
    Vector3d m_b = Vector3d::Zero();
    for (size_t k = s0; k < s1; ++k) m_b += (*in.mag_b)[k];
    m_b /= static_cast<double>(s1 - s0);
    if (!m_b.allFinite() || m_b.norm() == 0.0) return make_error("heading from the magnetometer: no field measured");
    yaw0 = ins::heading_from_magnetometer(m_b, level->roll, level->pitch, o.magnetic_declination_rad);
    const Vector3d m_level = R_n_b_from_euler(level->roll, level->pitch, 0.0) * m_b;  // yaw-free, z down
    sum.magnetometer_field_norm = m_b.norm();
    sum.magnetometer_dip_deg = std::atan2(m_level.z(), m_level.head<2>().norm()) * kRadToDeg;
    how += fmt::format("; heading from the magnetometer ({:.1f} deg incl. declination {:.1f} deg; field dip {:.1f} deg)",
                       yaw0 * kRadToDeg, o.magnetic_declination_rad * kRadToDeg, sum.magnetometer_dip_deg);
  } else if (o.initial_yaw_rad) {
    yaw0 = *o.initial_yaw_rad;
    how += "; heading from configuration";
  } else if (tc) {
    const ins::NavState nav_yaw0 = ins::nav_state_at_rest(samples[s0].t, p0, level->roll, level->pitch, 0.0);
    const auto heading = heading_from_motion(in, o, decisions, gnss, s0, nav_yaw0, imu0, sum, how);
    if (!heading) return heading.error();
    yaw0 = heading->yaw_rad;
    opt.initial_sigma_yaw_rad = heading->sigma_yaw_rad;
  } else {
    return make_error("mode ins needs an initial heading (initial.yaw_deg)");
  }
  sum.initial_yaw_deg = yaw0 * kRadToDeg;
  sum.initialization = how;
  ForwardRunner runner2(in, opt, decisions);
  PassOptions po;
  po.gnss = tc;
  if (!not_on_foot.empty()) po.hand_nhc_interval_s = 1.0;  // eq. 8.4 once per second
  const ins::NavState nav0 = ins::nav_state_at_rest(samples[s0].t, p0, level->roll, level->pitch, yaw0);
  if (auto ok = runner2.run(s0, nav0, imu0, po, result); !ok) return ok.error();
  sum.imu_samples_used = sum.imu_samples;
  if (s0 > 0) sum.imu_skipped["before_first_still_period"] += static_cast<long>(s0);
  sum.imu_samples += static_cast<long>(s0);  // samples before the start were used for levelling only
  return result;
}

}  // namespace pednav::fusion
