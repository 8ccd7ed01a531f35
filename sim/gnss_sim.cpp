// SPDX-License-Identifier: BSD-2-Clause
// GNSS observation simulation (docs/sim.md §6). For each epoch tag t (receiver time) and satellite s:
//   t_rx = t - dt_r (GPST reception), antenna at t_rx, transmit time from the light time incl. the delays,
//   P = rho + c dt_r - c (dt_s - TGD) + I + T + e_thermal + e_multipath (+ e_atm_sd + blunder at the rover)
//   -lambda D = rho_dot + c d(dt_r)/dt - c d(dt_s)/dt + e_doppler
//   lambda Phi = rho + c dt_r - c (dt_s - TGD) - I + T + lambda (N + h) + lambda e_pll + e_carrier_mp
//                (+ (1 - 2 f_iono) e_atm_sd at the rover)       (only with gnss.carrier_phase; docs/sim.md §8)
// rho and rho_dot from gnss::line_of_sight (Sagnac included), satellite states from gnss::satellite_state on the
// same ephemerides a reader of nav.rnx sees. I = 1.3 x Klobuchar, T = 1.05 x Saastamoinen (so undifferenced
// processing keeps a model error); the rover gets an extra single-difference residual that grows with baseline.
#include "sim/gnss_sim.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/geodesy.hpp"
#include "gnss/ephemeris.hpp"
#include "gnss/measurement.hpp"
#include "sim/random.hpp"

namespace pednav::sim {
namespace {

constexpr double kL1_hz = 1575.42e6;
constexpr double kLambdaL1_m = kSpeedOfLight_mps / kL1_hz;
constexpr double kChip_m = kSpeedOfLight_mps / 1.023e6;

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// Carrier phase of one receiver-satellite channel (docs/sim.md §8). Its random numbers come from the receiver's
// carrier stream only, so the code, Doppler and C/N0 draws are those of a simulation without carrier phase.
struct CarrierChannel {
  bool started = false;      // multipath process drawn
  bool locked = false;       // PLL in lock at the previous epoch
  bool ever_locked = false;  // locked at least once (a new lock after that is a loss of lock: LLI bit 0)
  double ambiguity = 0.0;    // integer ambiguity N, slips included [cycles]
  double half_cycle = 0.0;   // 0 or +-0.5 [cycles] while the half-cycle flag (LLI bit 1) is up
  GpsTime half_until;        // the half-cycle flag is up at epochs before this
  UnitGaussMarkov multipath;
};

// One receiver's per-satellite state.
struct Channel {
  bool tracked = false;
  double cn0_offset_db = 0.0;
  UnitGaussMarkov multipath, attenuation, atmosphere;
  double blunder_m = 0.0;
  GpsTime blunder_until;
  int blunder_id = 0;
  CarrierChannel carrier;
};

struct Receiver {
  const GnssOptions& o;
  bool is_rover;
  Rng rng;
  Rng carrier_rng;  // carrier phase only (docs/sim.md §8)
  std::map<int, Channel> ch;
  Receiver(const GnssOptions& opt, bool rover, uint64_t seed)
      : o(opt),
        is_rover(rover),
        rng(seed, rover ? kStreamRover : kStreamBase),
        carrier_rng(seed, rover ? kStreamCarrierRover : kStreamCarrierBase) {}
  Channel& channel(int prn) {
    auto it = ch.find(prn);
    if (it != ch.end()) return it->second;
    Channel c;
    c.cn0_offset_db = o.cn0_satellite_sd_db * rng.normal();
    c.multipath = UnitGaussMarkov(o.multipath_tau_s, rng);
    c.attenuation = UnitGaussMarkov(1.0, rng);
    c.atmosphere = UnitGaussMarkov(o.atmosphere_tau_s, rng);
    return ch.emplace(prn, c).first->second;
  }
};

// Attenuation [dB] at route distance route_m for a channel whose GM value is u (+inf: indoor).
double attenuation_db(const GnssOptions& o, double route_m, double u) {
  for (const auto& seg : o.attenuation) {
    if (route_m < seg.from_m || route_m >= seg.to_m) continue;
    if (seg.type == "indoor") return INFINITY;
    if (seg.type == "foliage") return seg.min_db + (seg.max_db - seg.min_db) * normal_cdf(u);
    return 0.0;
  }
  return 0.0;
}
double attenuation_tau_s(const GnssOptions& o, double route_m) {
  for (const auto& seg : o.attenuation)
    if (route_m >= seg.from_m && route_m < seg.to_m) return seg.tau_s;
  return 10.0;
}

// Uniform integer in [-max, max].
double uniform_integer(Rng& rng, int max) {
  const double n = std::floor(rng.uniform() * (2.0 * max + 1.0));
  return std::min(n, 2.0 * max) - max;
}

// Lock, slips and half-cycle state of one tracked signal at epoch `tag` (docs/sim.md §8, eq. 8.5-8.6). Returns the
// LLI bits of the observation, or -1 while the PLL is out of lock (no phase written). cn0 is the measured C/N0 (lock
// decisions, as the code's tracking), cn0_true the noise-free one (slip rate). Events go to `events`.
int carrier_lock(const GnssOptions& o, CarrierChannel& cc, Rng& rng, GpsTime tag, double dt, double cn0,
                 double cn0_true, bool rover, gnss::SatId sat, std::vector<CarrierEvent>& events) {
  const bool lock = cc.locked ? cn0 >= o.carrier_tracking_threshold_dbhz : cn0 >= o.carrier_acquisition_threshold_dbhz;
  if (!lock) {
    cc.locked = false;
    return -1;
  }
  int lli = 0;
  if (!cc.locked) {  // (re-)acquisition: a new integer ambiguity, possibly a half-cycle ambiguity
    const double n = uniform_integer(rng, o.carrier_ambiguity_max_cycles);
    if (cc.ever_locked) {
      lli |= 1;
      events.push_back({tag, rover, sat, CarrierEventKind::kLossOfLock, n - cc.ambiguity});
    }
    cc.ambiguity = n;
    cc.locked = cc.ever_locked = true;
    cc.half_cycle = 0.0;
    if (rng.uniform() < o.carrier_half_cycle_probability) {
      cc.half_cycle = rng.uniform() < 0.5 ? -0.5 : 0.5;
      cc.half_until = tag.plus_s(o.carrier_half_cycle_s);
      events.push_back({tag, rover, sat, CarrierEventKind::kHalfCycle, cc.half_cycle});
    }
  } else if (rng.uniform() < -std::expm1(-carrier_slip_rate_per_s(o, cn0_true) * dt)) {  // eq. 8.5: Poisson
    const double size = 1.0 + std::floor(rng.uniform() * o.carrier_slip_max_cycles);     // 1..max (uniform() < 1)
    const double jump = rng.uniform() < 0.5 ? -size : size;
    const bool flagged = rng.uniform() < o.carrier_slip_flagged_fraction;
    cc.ambiguity += jump;
    if (flagged) lli |= 1;
    events.push_back(
        {tag, rover, sat, flagged ? CarrierEventKind::kSlipFlagged : CarrierEventKind::kSlipUnflagged, jump});
  }
  if (cc.half_cycle != 0.0 && !(tag < cc.half_until)) cc.half_cycle = 0.0;  // the receiver resolved it
  if (cc.half_cycle != 0.0) lli |= 2;
  return lli;
}

}  // namespace

const char* carrier_event_name(CarrierEventKind kind) {
  switch (kind) {
    case CarrierEventKind::kLossOfLock: return "loss_of_lock";
    case CarrierEventKind::kSlipFlagged: return "slip_flagged";
    case CarrierEventKind::kSlipUnflagged: return "slip_unflagged";
    case CarrierEventKind::kHalfCycle: return "half_cycle";
  }
  return "unknown";
}

double pll_phase_sigma_cycles(const GnssOptions& o, double cn0_dbhz) {
  const double cn0 = std::pow(10.0, cn0_dbhz / 10.0);
  return std::sqrt(o.pll_bandwidth_hz / cn0 * (1.0 + 1.0 / (2.0 * o.pll_integration_time_s * cn0))) / (2.0 * kPi);
}
double carrier_multipath_sigma_m(const GnssOptions& o, double cn0_dbhz) {
  return std::min(kLambdaL1_m / 12.0, o.carrier_multipath_sigma_m *
                                          std::pow(10.0, std::max(0.0, o.multipath_cn0_ref_dbhz - cn0_dbhz) / 20.0));
}
double carrier_slip_rate_per_s(const GnssOptions& o, double cn0_dbhz) {
  return o.carrier_slip_rate_per_s *
         std::pow(10.0, -(cn0_dbhz - o.carrier_tracking_threshold_dbhz) / o.carrier_slip_decade_db);
}

double thermal_code_sigma_m(const GnssOptions& o, double cn0_dbhz) {
  const double cn0 = std::pow(10.0, cn0_dbhz / 10.0), d = o.correlator_spacing_chips;
  return kChip_m * std::sqrt(o.dll_bandwidth_hz * d / (2.0 * cn0) * (1.0 + 2.0 / ((2.0 - d) * o.integration_time_s * cn0)));
}
double multipath_sigma_m(const GnssOptions& o, double cn0_dbhz) {
  return o.multipath_sigma_m * std::pow(10.0, std::max(0.0, o.multipath_cn0_ref_dbhz - cn0_dbhz) / 20.0);
}
double doppler_sigma_mps(const GnssOptions& o, double cn0_dbhz) {
  return o.doppler_sigma_mps * std::pow(10.0, std::max(0.0, o.multipath_cn0_ref_dbhz - cn0_dbhz) / 20.0);
}

gnss::WeightModel receiver_weight_model(const GnssOptions& o) {
  gnss::WeightModel w;
  w.cn0_ref_dbhz = o.cn0_zenith_dbhz;
  w.code_sigma_zenith_m = thermal_code_sigma_m(o, o.cn0_zenith_dbhz);
  // doppler_sigma_mps(cn0) = σ_d 10^((ref_mp − cn0)/20) below ref_mp = [σ_d 10^((ref_mp − zenith)/20)] 10^((zenith − cn0)/20).
  w.doppler_sigma_zenith_mps = o.doppler_sigma_mps * std::pow(10.0, (o.multipath_cn0_ref_dbhz - o.cn0_zenith_dbhz) / 20.0);
  w.elevation_weight = 0.0;
  w.code_squaring_loss =
      2.0 / ((2.0 - o.correlator_spacing_chips) * o.integration_time_s * std::pow(10.0, o.cn0_zenith_dbhz / 10.0));
  return w;
}

double receiver_carrier_sigma_zenith_m(const GnssOptions& o) {
  return std::hypot(carrier_multipath_sigma_m(o, o.cn0_zenith_dbhz),
                    kLambdaL1_m * pll_phase_sigma_cycles(o, o.cn0_zenith_dbhz));
}

GnssSimulation simulate_gnss(const GnssOptions& o, const gnss::NavData& nav, const AntennaFunction& rover_antenna,
                             const Eigen::Vector3d& p_base_e, GpsTime t_begin, GpsTime t_end, uint64_t seed) {
  GnssSimulation out;
  out.p_base_e = p_base_e;
  Receiver rx_rover(o, true, seed), rx_base(o, false, seed);
  Rng clock_rng(seed, kStreamClocks), blunder_rng(seed, kStreamBlunders);
  std::vector<int> prns;
  for (const auto& e : nav.kepler)
    if (std::find(prns.begin(), prns.end(), e.sat.prn) == prns.end()) prns.push_back(e.sat.prn);
  std::sort(prns.begin(), prns.end());

  const int64_t step_ns = std::llround(1e9 / o.rate_hz);
  const double dt = static_cast<double>(step_ns) * 1e-9;
  int64_t k0 = t_begin.ns() / step_ns;
  if (k0 * step_ns < t_begin.ns()) ++k0;
  ClockOptions cr = o.rover_clock, cb = o.base_clock;
  const AntennaFunction base_antenna = [&](GpsTime) { return AntennaTruth{p_base_e, Eigen::Vector3d::Zero(), 0.0}; };

  for (int64_t k = k0; k * step_ns <= t_end.ns(); ++k) {
    const GpsTime tag = GpsTime::from_ns(k * step_ns);
    if (k > k0) {  // two-state clocks: bias integrates drift, drift random-walks
      cr.bias_s += cr.drift * dt;
      cr.drift += cr.drift_rw * std::sqrt(dt) * clock_rng.normal();
      cb.bias_s += cb.drift * dt;
      cb.drift += cb.drift_rw * std::sqrt(dt) * clock_rng.normal();
    }
    out.clocks.push_back({tag, cr.bias_s, cr.drift, cb.bias_s, cb.drift});
    for (int r = 0; r < 2; ++r) {
      const bool is_rover = r == 0;
      Receiver& rx = is_rover ? rx_rover : rx_base;
      const ClockOptions& clk = is_rover ? cr : cb;
      const GpsTime t_rx = tag.plus_s(-clk.bias_s);
      const AntennaTruth ant = (is_rover ? rover_antenna : base_antenna)(t_rx);
      const Geodetic llh = geodetic_from_ecef(ant.p_e);
      const double baseline_m = (ant.p_e - p_base_e).norm();
      gnss::ObsEpoch epoch;
      epoch.time = tag;
      for (const int prn : prns) {
        const gnss::SatId sat{gnss::System::kGps, prn};
        Channel& c = rx.channel(prn);
        // Geometry: iterate the transmit time (flight time incl. atmospheric delays).
        double flight_s = 0.075, iono = 0.0, tropo = 0.0;
        gnss::SatState ss;
        gnss::LineOfSight los;
        gnss::ElevationAzimuth ea;
        bool ok = true;
        for (int it = 0; it < 3 && ok; ++it) {
          auto st = gnss::satellite_state(nav, sat, t_rx.plus_s(-flight_s));
          if (!st) {
            ok = false;
            break;
          }
          ss = *st;
          los = gnss::line_of_sight(ss, ant.p_e, ant.v_e);
          ea = gnss::elevation_azimuth(ant.p_e, ss.p_es_e);
          if (ea.elevation > 0.0) {
            iono = kIonoTruthFactor * gnss::klobuchar_delay_m(nav.klobuchar, t_rx, llh, ea);
            tropo = kTropoTruthFactor * gnss::saastamoinen_delay_m(llh, ea.elevation);
          }
          flight_s = (los.range_m + iono + tropo) / kSpeedOfLight_mps;
        }
        // Correlated processes advance every epoch, visible or not (their statistics stay stationary).
        c.multipath.step(dt, rx.rng);
        c.atmosphere.step(dt, rx.rng);
        const double u_att = c.attenuation.step(dt / std::max(1e-3, attenuation_tau_s(o, ant.route_m)), rx.rng);
        const double cn0_noise = o.cn0_noise_db * rx.rng.normal();
        const double w_thermal = rx.rng.normal(), w_doppler = rx.rng.normal();
        double w_phase = 0.0;
        if (o.carrier_phase) {  // the carrier's own processes, from the carrier stream (docs/sim.md §8)
          CarrierChannel& cc = c.carrier;
          if (!cc.started) {
            cc.multipath = UnitGaussMarkov(o.carrier_multipath_tau_s, rx.carrier_rng);
            cc.started = true;
          }
          cc.multipath.step(dt, rx.carrier_rng);
          w_phase = rx.carrier_rng.normal();
        }
        if (!ok || ea.elevation < o.elevation_mask_rad) {
          c.tracked = false;
          c.carrier.locked = false;
          continue;
        }
        const double sin_el = std::sin(ea.elevation);
        const double att = is_rover ? attenuation_db(o, ant.route_m, u_att) : 0.0;
        const double cn0_true = o.cn0_zenith_dbhz - (o.cn0_zenith_dbhz - o.cn0_horizon_dbhz) * (1.0 - sin_el) +
                                c.cn0_offset_db - att;
        const double cn0 = cn0_true + cn0_noise;
        if (!std::isfinite(cn0)) {
          c.tracked = false;
          c.carrier.locked = false;
          continue;
        }
        c.tracked = c.tracked ? cn0 >= o.tracking_threshold_dbhz : cn0 >= o.acquisition_threshold_dbhz;
        if (!c.tracked) {
          c.carrier.locked = false;
          continue;
        }
        const double clock_m = kSpeedOfLight_mps * (clk.bias_s - (ss.clock_bias_s - ss.group_delay_s));
        double P = los.range_m + clock_m + iono + tropo + thermal_code_sigma_m(o, cn0_true) * w_thermal +
                   multipath_sigma_m(o, cn0_true) * c.multipath.value();
        const double atm_sd_m =
            is_rover ? o.atmosphere_sd_ppm * 1e-6 * baseline_m / std::max(0.1, sin_el) * c.atmosphere.value() : 0.0;
        if (is_rover) {
          P += atm_sd_m;
          ++out.rover_sat_epochs;
          if (tag >= c.blunder_until && o.blunder_rate > 0.0 && blunder_rng.uniform() < o.blunder_rate) {
            const double mag = blunder_rng.uniform(o.blunder_min_m, o.blunder_max_m);
            c.blunder_m = blunder_rng.uniform() < 0.5 ? -mag : mag;
            const double dur = blunder_rng.uniform(o.blunder_min_s, o.blunder_max_s);
            c.blunder_until = tag.plus_s(std::max(dt, std::round(dur / dt) * dt) - 0.5 * dt);
            c.blunder_id = ++out.blunder_events;
          }
          if (tag < c.blunder_until) {
            P += c.blunder_m;
            out.blunders.push_back({tag, sat, c.blunder_m, c.blunder_id});
          }
        }
        const double rr = los.range_rate_mps + kSpeedOfLight_mps * (clk.drift - ss.clock_drift_sps) +
                          doppler_sigma_mps(o, cn0_true) * w_doppler;
        gnss::SatObs so;
        so.sat = sat;
        so.pseudorange_m = P;
        so.doppler_hz = -rr / kLambdaL1_m;
        so.cn0_dbhz = cn0;
        so.wavelength_m = kLambdaL1_m;
        if (o.carrier_phase) {
          const int lli =
              carrier_lock(o, c.carrier, rx.carrier_rng, tag, dt, cn0, cn0_true, is_rover, sat, out.carrier_events);
          if (lli >= 0) {
            // eq. 8.1: the code's geometry, clocks and troposphere; the ionosphere advances the phase, and the residual
            // SD atmosphere enters as its tropospheric share minus its ionospheric share (eq. 8.2).
            const double f_iono = o.atmosphere_sd_iono_fraction;
            const double phase_m = los.range_m + clock_m - iono + tropo + (1.0 - 2.0 * f_iono) * atm_sd_m +
                                   carrier_multipath_sigma_m(o, cn0_true) * c.carrier.multipath.value();
            so.carrier_cycles = phase_m / kLambdaL1_m + c.carrier.ambiguity + c.carrier.half_cycle +
                                pll_phase_sigma_cycles(o, cn0_true) * w_phase;
            so.lli = static_cast<uint8_t>(lli);
            out.carrier_truth.push_back({tag, is_rover, sat, c.carrier.ambiguity, c.carrier.half_cycle});
          }
        }
        epoch.sats.push_back(so);
      }
      if (!epoch.sats.empty()) (is_rover ? out.rover : out.base).epochs.push_back(std::move(epoch));
    }
  }
  out.rover.approx_position_e = rover_antenna(t_begin).p_e;
  out.rover.has_approx_position = true;
  out.rover.marker_name = "ROVER";
  out.base.approx_position_e = p_base_e;
  out.base.has_approx_position = true;
  out.base.marker_name = "BASE";
  out.rover.rinex_version = out.base.rinex_version = 3.04;
  return out;
}

}  // namespace pednav::sim
