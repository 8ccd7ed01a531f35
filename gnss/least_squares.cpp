// SPDX-License-Identifier: BSD-2-Clause
// Epoch least squares with FDE; see gnss/least_squares.hpp and docs/gnss.md ("Epoch solver").
#include "gnss/least_squares.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace pednav::gnss {
namespace {

constexpr double kC = kSpeedOfLight_mps;
constexpr double kMinEarthRadius_m = 6.0e6;  // below: no valid position yet, elevation mask not applicable

// One usable satellite of the epoch (rover signal, optional base signal, weights).
struct Candidate {
  SatId sat;
  SignalAtReceiver rover, base;
  double cn0_rover = kNaN, cn0_base = kNaN;
  double elevation_base = kPi / 2;  // base elevation (for its weight)
  double elevation = kPi / 2;
  bool active = true;
};

// Regularized lower incomplete gamma P(a, x) (Numerical Recipes-style series / continued fraction).
double gamma_p(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double gln = std::lgamma(a);
  if (x < a + 1.0) {
    double sum = 1.0 / a, del = sum, ap = a;
    for (int n = 0; n < 500; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1.0 - a, c = 1e300, d = 1.0 / b, h = d;
  for (int i = 1; i < 500; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return 1.0 - std::exp(-x + a * std::log(x) - gln) * h;
}

int system_index(std::vector<System>& systems, System s) {
  auto it = std::find(systems.begin(), systems.end(), s);
  if (it != systems.end()) return static_cast<int>(it - systems.begin());
  systems.push_back(s);
  return static_cast<int>(systems.size()) - 1;
}

double code_sigma(const Candidate& c, const SolverOptions& o, bool sd) {
  const double f = c.sat.system == System::kGlonass ? o.weights.glonass_code_factor : 1.0;
  const double sr = f * measurement_sigma(o.weights, c.cn0_rover, c.elevation, false);
  if (!sd) return sr;
  const double sb = f * measurement_sigma(o.weights, c.cn0_base, c.elevation_base, false);
  return std::sqrt(sr * sr + sb * sb);
}

double doppler_sigma(const Candidate& c, const SolverOptions& o, bool sd) {
  const double sr = measurement_sigma(o.weights, c.cn0_rover, c.elevation, true);
  if (!sd) return sr;
  const double sb = measurement_sigma(o.weights, c.cn0_base, c.elevation_base, true);
  return std::sqrt(sr * sr + sb * sb);
}

// Result of one weighted Gauss-Newton solve over the active rows.
struct WlsResult {
  bool ok = false;
  Eigen::VectorXd x;           // final state
  Eigen::MatrixXd H;           // Jacobian at the solution (active rows)
  Eigen::VectorXd r, sigma;    // residuals and sigmas (active rows)
  std::vector<int> rows;       // candidate index of each active row
  Eigen::MatrixXd cov;         // (H^T W H)^-1
};

// Normalized residuals w_i = r_i / sqrt(Q_r,ii), Q_r = Sigma - H (H^T W H)^-1 H^T (Baarda's w-test).
Eigen::VectorXd normalized_residuals(const WlsResult& s) {
  const Eigen::Index n = s.r.size();
  Eigen::VectorXd w(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double q = s.sigma(i) * s.sigma(i) - s.H.row(i) * s.cov * s.H.row(i).transpose();
    w(i) = q > 1e-12 * s.sigma(i) * s.sigma(i) ? std::abs(s.r(i)) / std::sqrt(q) : 0.0;
  }
  return w;
}

double weighted_sse(const WlsResult& s) { return (s.r.array() / s.sigma.array()).square().sum(); }

}  // namespace

const char* reject_reason_name(RejectReason r) {
  switch (r) {
    case RejectReason::kNoPseudorange: return "no_pseudorange";
    case RejectReason::kLowCn0: return "low_cn0";
    case RejectReason::kNoEphemeris: return "no_ephemeris";
    case RejectReason::kNotAtBase: return "not_at_base";
    case RejectReason::kBelowElevationMask: return "below_elevation_mask";
    case RejectReason::kCodeFault: return "code_fault_excluded";
    case RejectReason::kDopplerFault: return "doppler_fault_excluded";
    case RejectReason::kCount: break;
  }
  return "?";
}

const char* epoch_failure_name(EpochFailure f) {
  switch (f) {
    case EpochFailure::kNone: return "solved";
    case EpochFailure::kNoBaseEpoch: return "no_base_epoch_within_max_age";
    case EpochFailure::kTooFewSatellites: return "too_few_satellites";
    case EpochFailure::kNotConverged: return "not_converged";
    case EpochFailure::kCount: break;
  }
  return "?";
}

double chi_square_quantile(double p, int dof) {
  // The callers ask for the same few (p, dof) at every epoch (the RAIM and w-test thresholds): the last answers
  // are kept per thread (Monte Carlo runs filters in parallel), keyed by p, for dof < 64.
  constexpr int kCachedDof = 64;
  thread_local double cached_p = std::numeric_limits<double>::quiet_NaN();
  thread_local std::array<double, kCachedDof> cached{};
  const bool cacheable = dof >= 0 && dof < kCachedDof;
  if (cacheable) {
    if (p != cached_p) {
      cached_p = p;
      cached.fill(-1.0);
    } else if (cached[static_cast<size_t>(dof)] >= 0.0) {
      return cached[static_cast<size_t>(dof)];
    }
  }
  // Bisection on the CDF P(dof/2, x/2).
  double lo = 0.0, hi = std::max(10.0, 10.0 * dof);
  while (gamma_p(0.5 * dof, 0.5 * hi) < p) hi *= 2.0;
  for (int i = 0; i < 100 && hi - lo > 1e-10 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (gamma_p(0.5 * dof, 0.5 * mid) < p ? lo : hi) = mid;
  }
  const double q = 0.5 * (lo + hi);
  if (cacheable) cached[static_cast<size_t>(dof)] = q;
  return q;
}

EpochSolution solve_epoch(const NavData& nav, const ObsEpoch& rover, const ObsEpoch* base,
                          const Eigen::Vector3d& p_eb_e, const Eigen::Vector3d& p_init_e,
                          const SolverOptions& o) {
  EpochSolution sol;
  sol.time = rover.time;
  const bool sd = base != nullptr;
  auto reject = [&sol](RejectReason r) { ++sol.rejections[static_cast<int>(r)]; };

  // 1. Candidates: code present, C/N0 high enough, ephemeris, base signal (SD).
  std::vector<Candidate> cands;
  cands.reserve(rover.sats.size());
  for (const SatObs& so : rover.sats) {
    if (std::isnan(so.pseudorange_m)) { reject(RejectReason::kNoPseudorange); continue; }
    if (!std::isnan(so.cn0_dbhz) && so.cn0_dbhz < o.min_cn0_dbhz) { reject(RejectReason::kLowCn0); continue; }
    Candidate c;
    c.sat = so.sat;
    c.cn0_rover = so.cn0_dbhz;
    c.rover.pseudorange_m = so.pseudorange_m;
    c.rover.range_rate_mps = -so.wavelength_m * so.doppler_hz;
    if (sd) {
      auto it = std::find_if(base->sats.begin(), base->sats.end(), [&](const SatObs& b) { return b.sat == so.sat; });
      if (it == base->sats.end() || std::isnan(it->pseudorange_m) ||
          (!std::isnan(it->cn0_dbhz) && it->cn0_dbhz < o.min_cn0_dbhz)) {
        reject(RejectReason::kNotAtBase);
        continue;
      }
      c.cn0_base = it->cn0_dbhz;
      c.base.pseudorange_m = it->pseudorange_m;
      c.base.range_rate_mps = -it->wavelength_m * it->doppler_hz;
      auto sb = satellite_state_at_reception(nav, so.sat, base->time, it->pseudorange_m);
      if (!sb) { reject(RejectReason::kNoEphemeris); continue; }
      c.base.sat = *sb;
      c.elevation_base = elevation_azimuth(p_eb_e, sb->p_es_e).elevation;
    }
    auto sr = satellite_state_at_reception(nav, so.sat, rover.time, so.pseudorange_m);
    if (!sr) { reject(RejectReason::kNoEphemeris); continue; }
    c.rover.sat = *sr;
    cands.push_back(c);
  }

  // 2. Code solution. State x = [p_ea_e (3), c*dt per constellation].
  Eigen::Vector3d p = p_init_e;
  if (p.norm() < kMinEarthRadius_m && sd) p = p_eb_e;
  const std::array<double, 8>& klob = nav.klobuchar;

  auto apply_mask = [&](const Eigen::Vector3d& pos) {
    if (pos.norm() < kMinEarthRadius_m) return;
    for (Candidate& c : cands) {
      c.elevation = elevation_azimuth(pos, c.rover.sat.p_es_e).elevation;
    }
  };

  auto solve_code = [&](Eigen::Vector3d p0) -> WlsResult {
    WlsResult res;
    std::vector<System> systems;
    std::vector<int> rows;
    for (int i = 0; i < static_cast<int>(cands.size()); ++i) {
      if (cands[i].active) rows.push_back(i), system_index(systems, cands[i].sat.system);
    }
    const int n_clk = static_cast<int>(systems.size());
    const int m = 3 + n_clk;
    if (static_cast<int>(rows.size()) < m) return res;
    Eigen::VectorXd x = Eigen::VectorXd::Zero(m);
    x.head<3>() = p0;
    const int n = static_cast<int>(rows.size());
    Eigen::MatrixXd H(n, m);
    Eigen::VectorXd r(n), sigma(n);
    for (int it = 0; it < o.max_iterations + 10; ++it) {
      const Eigen::Vector3d pos = x.head<3>();
      const bool pos_valid = pos.norm() > kMinEarthRadius_m;
      const Geodetic llh = pos_valid ? geodetic_from_ecef(pos) : Geodetic{};
      H.setZero();
      for (int k = 0; k < n; ++k) {
        Candidate& c = cands[rows[k]];
        const int ci = system_index(systems, c.sat.system);
        MeasurementRow row;
        if (sd) {
          row = sd_pseudorange(c.sat, c.rover, c.base, pos, p_eb_e, x(3 + ci));
        } else {
          double iono = 0.0, tropo = 0.0;
          if (pos_valid) {
            const ElevationAzimuth ea = elevation_azimuth(pos, c.rover.sat.p_es_e);
            c.elevation = ea.elevation;
            double scale = 1.0;  // Klobuchar is for GPS L1; other bands scale with (f_L1/f)^2 (1/f^2 law)
            if (c.sat.system == System::kGlonass) scale = std::pow(1575.42 / 1602.0, 2);
            if (c.sat.system == System::kBeidou) scale = std::pow(1575.42 / 1561.098, 2);
            if (nav.has_klobuchar) iono = scale * klobuchar_delay_m(klob, rover.time, llh, ea);
            tropo = saastamoinen_delay_m(llh, ea.elevation);
          }
          row = ud_pseudorange(c.sat, c.rover, pos, x(3 + ci), iono, tropo);
        }
        H.block<1, 3>(k, 0) = row.J_p;
        H(k, 3 + ci) = row.J_clock;
        r(k) = row.residual;
        sigma(k) = code_sigma(c, o, sd);
      }
      const Eigen::MatrixXd Hw = (H.array().colwise() / sigma.array()).matrix();
      const Eigen::VectorXd rw = r.array() / sigma.array();
      const Eigen::MatrixXd N = Hw.transpose() * Hw;
      Eigen::LDLT<Eigen::MatrixXd> ldlt(N);
      if (ldlt.info() != Eigen::Success || ldlt.rcond() < 1e-12) return res;
      const Eigen::VectorXd dx = ldlt.solve(Hw.transpose() * rw);
      x += dx;
      if (dx.head<3>().norm() < o.convergence_m && it > 0) {
        res.ok = true;
        res.x = x;
        res.H = H;
        // residuals at the final state
        res.r = r - H * dx;
        res.sigma = sigma;
        res.rows = rows;
        res.cov = ldlt.solve(Eigen::MatrixXd::Identity(m, m));
        sol.clock_m.clear();
        for (int s = 0; s < n_clk; ++s) sol.clock_m.emplace_back(systems[s], x(3 + s));
        return res;
      }
    }
    return res;
  };

  // Start far from the solution (undifferenced, no initial position): solve once unmasked to get a position.
  if (p.norm() < kMinEarthRadius_m) {
    WlsResult first = solve_code(p);
    if (first.ok) p = first.x.head<3>();
  }
  apply_mask(p);
  for (Candidate& c : cands) {
    if (c.elevation < o.elevation_mask_rad) { c.active = false; reject(RejectReason::kBelowElevationMask); }
  }

  WlsResult best = solve_code(p);
  if (!best.ok) {
    int active = 0;
    for (const Candidate& c : cands) active += c.active;
    sol.failure = active < 4 ? EpochFailure::kTooFewSatellites : EpochFailure::kNotConverged;
    if (active >= 4) {
      // too few for the number of clocks counts as too few satellites too
      std::vector<System> s;
      for (const Candidate& c : cands) if (c.active) system_index(s, c.sat.system);
      if (active < 3 + static_cast<int>(s.size())) sol.failure = EpochFailure::kTooFewSatellites;
    }
    return sol;
  }
  // Elevations at the solution; a satellite that falls below the mask there is dropped once.
  apply_mask(best.x.head<3>());
  bool dropped = false;
  for (Candidate& c : cands) {
    if (c.active && c.elevation < o.elevation_mask_rad) {
      c.active = false;
      dropped = true;
      reject(RejectReason::kBelowElevationMask);
    }
  }
  if (dropped) {
    best = solve_code(best.x.head<3>());
    if (!best.ok) { sol.failure = EpochFailure::kTooFewSatellites; return sol; }
  }

  // 3. FDE: global test, then exclude the worst normalized residual while redundancy >= 2 before exclusion.
  const double local_threshold = std::sqrt(chi_square_quantile(o.fault_probability, 1));
  for (;;) {
    const int dof = static_cast<int>(best.r.size() - best.x.size());
    if (dof <= 0) break;
    const bool global_ok = weighted_sse(best) <= chi_square_quantile(o.fault_probability, dof);
    sol.global_test_passed = global_ok;
    if (global_ok || dof < 2) break;
    const Eigen::VectorXd w = normalized_residuals(best);
    Eigen::Index worst = 0;
    const double wmax = w.maxCoeff(&worst);
    if (wmax < local_threshold) break;
    cands[best.rows[worst]].active = false;
    WlsResult next = solve_code(best.x.head<3>());
    if (!next.ok) { cands[best.rows[worst]].active = true; break; }
    reject(RejectReason::kCodeFault);
    ++sol.n_sats_rejected;
    best = next;
  }
  sol.p_ea_e = best.x.head<3>();
  const int dof = static_cast<int>(best.r.size() - best.x.size());
  const double variance_factor = dof > 0 ? std::max(1.0, weighted_sse(best) / dof) : 1.0;
  sol.cov_p_e = best.cov.topLeftCorner<3, 3>() * variance_factor;
  sol.n_sats_used = static_cast<int>(best.rows.size());
  for (int i : best.rows) sol.used.push_back(cands[i].sat);
  {
    // DOPs from the unweighted geometry in ENU.
    const Geodetic llh = geodetic_from_ecef(sol.p_ea_e);
    const Eigen::Matrix3d R_e_n_ = R_e_n(llh.lat, llh.lon);
    Eigen::MatrixXd G = best.H;
    G.leftCols<3>() = best.H.leftCols<3>() * R_e_n_;  // NED columns
    const Eigen::MatrixXd Q = (G.transpose() * G).inverse();
    sol.dops.gdop = std::sqrt(Q.trace());
    sol.dops.pdop = std::sqrt(Q.topLeftCorner<3, 3>().trace());
    sol.dops.hdop = std::sqrt(Q(0, 0) + Q(1, 1));
    sol.dops.vdop = std::sqrt(Q(2, 2));
  }

  // 4. Velocity + drift from Doppler of the satellites of the code solution. State y = [v_ea_e (3), c*ddt].
  std::vector<int> drows;
  for (int i : best.rows) {
    const Candidate& c = cands[i];
    if (!std::isnan(c.rover.range_rate_mps) && (!sd || !std::isnan(c.base.range_rate_mps))) drows.push_back(i);
  }
  Eigen::Vector4d y = Eigen::Vector4d::Zero();
  for (;;) {
    const int n = static_cast<int>(drows.size());
    if (n < 4) break;
    Eigen::MatrixXd H(n, 4);
    Eigen::VectorXd r(n), sigma(n);
    Eigen::Vector4d yy = Eigen::Vector4d::Zero();
    Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
    for (int it = 0; it < 3; ++it) {  // linear in v and drift: 2 passes reach machine precision
      for (int k = 0; k < n; ++k) {
        const Candidate& c = cands[drows[k]];
        const MeasurementRow row =
            sd ? sd_range_rate(c.sat, c.rover, c.base, sol.p_ea_e, yy.head<3>(), p_eb_e, yy(3))
               : ud_range_rate(c.sat, c.rover, sol.p_ea_e, yy.head<3>(), yy(3));
        H.block<1, 3>(k, 0) = row.J_v;
        H(k, 3) = row.J_drift;
        r(k) = row.residual;
        sigma(k) = doppler_sigma(c, o, sd);
      }
      const Eigen::MatrixXd Hw = (H.array().colwise() / sigma.array()).matrix();
      const Eigen::Matrix4d N = Hw.transpose() * Hw;
      cov = N.inverse();
      const Eigen::Vector4d dy = cov * (Hw.transpose() * (r.array() / sigma.array()).matrix());
      yy += dy;
      r -= H * dy;
    }
    WlsResult s;
    s.H = H;
    s.r = r;
    s.sigma = sigma;
    s.cov = cov;
    const int vdof = n - 4;
    const double sse = weighted_sse(s);
    if (vdof >= 2 && sse > chi_square_quantile(o.fault_probability, vdof)) {
      const Eigen::VectorXd w = normalized_residuals(s);
      Eigen::Index worst = 0;
      if (w.maxCoeff(&worst) >= local_threshold) {
        drows.erase(drows.begin() + worst);
        reject(RejectReason::kDopplerFault);
        continue;
      }
    }
    y = yy;
    sol.velocity_ok = true;
    sol.n_doppler_used = n;
    sol.cov_v_e = cov.topLeftCorner<3, 3>() * (vdof > 0 ? std::max(1.0, sse / vdof) : 1.0);
    break;
  }
  sol.v_ea_e = y.head<3>();
  sol.drift_mps = y(3);
  return sol;
}

}  // namespace pednav::gnss
