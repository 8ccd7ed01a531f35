// SPDX-License-Identifier: BSD-2-Clause
#include "ins/saturation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include <Eigen/QR>

namespace pednav::ins {
namespace {

double value(const ImuSample& s, bool gyro, int axis) { return gyro ? s.omega_ib_b(axis) : s.f_ib_b(axis); }

// Least-squares polynomial of degree `deg` through (t_i, y_i), evaluated at t; time normalized for conditioning.
class PolyFit {
 public:
  PolyFit(const std::vector<double>& t, const std::vector<double>& y, int deg, double t_c, double h)
      : deg_(deg), t_c_(t_c), h_(h) {
    Eigen::MatrixXd A(static_cast<Eigen::Index>(t.size()), deg + 1);
    Eigen::VectorXd b(static_cast<Eigen::Index>(t.size()));
    for (size_t i = 0; i < t.size(); ++i) {
      const double u = (t[i] - t_c_) / h_;
      double p = 1.0;
      for (int k = 0; k <= deg; ++k, p *= u) A(static_cast<Eigen::Index>(i), k) = p;
      b(static_cast<Eigen::Index>(i)) = y[i];
    }
    c_ = A.colPivHouseholderQr().solve(b);
  }
  double operator()(double t) const {
    const double u = (t - t_c_) / h_;
    double v = 0.0;
    for (int k = deg_; k >= 0; --k) v = v * u + c_(k);
    return v;
  }

 private:
  int deg_;
  double t_c_, h_;
  Eigen::VectorXd c_;
};

}  // namespace

// docs/ins.md §9. For a run k = first..last clipped at ±r on one axis, with n unclipped samples on each side:
//   x̂(t) = p₄(t), the degree-4 least-squares polynomial through the 2n neighbours                     (9.1)
//   v_k = sign · min(max(sign · x̂(t_k), r), c_max r),  added A = Σ_k (|v_k| − r) Δt_k                  (9.2)
//   σ_A = max(κ A, |A − A₂|), A₂ from the degree-2 fit through the n − 1 nearest neighbours per side   (9.3)
// with Δt_k = (t_{k+1} − t_{k−1}) / 2. A run that cannot be reconstructed keeps its clipped values and gets
// σ_A = r T / 2 (the excess rate is taken as up to the range itself over the run's duration T).
SaturationRepair repair_saturation(const std::vector<ImuSample>& samples, const SaturationOptions& o) {
  SaturationRepair out;
  const size_t n = samples.size();
  const int nf = std::max(3, o.fit_samples);
  std::map<size_t, SaturationRepair::Sample> repaired;
  for (const bool gyro : {true, false}) {
    const double r = gyro ? o.gyro_range_radps : o.accel_range_mps2;
    if (!(r > 0.0) || n == 0) continue;
    long above = 0;
    double max_abs = 0.0;  // largest finite |value| on any axis: below the clip level, no run to look for
    for (const auto& s : samples) {
      const Eigen::Vector3d& x = gyro ? s.omega_ib_b : s.f_ib_b;
      if (x.allFinite() && x.cwiseAbs().maxCoeff() > 1.01 * r) ++above;
      for (int a = 0; a < 3; ++a) {
        if (std::isfinite(x(a))) max_abs = std::max(max_abs, std::abs(x(a)));
      }
    }
    if (above > 0) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "%ld samples exceed the %s range %.4g %s by > 1 %%: the configured range is not the device's, "
                    "saturation not checked",
                    above, gyro ? "gyro" : "accelerometer", r, gyro ? "rad/s" : "m/s^2");
      out.notes.emplace_back(buf);
      continue;
    }
    const double lim = o.level * r;
    if (max_abs < lim) continue;
    auto clipped = [&](size_t k, int axis) {
      const double v = value(samples[k], gyro, axis);
      return std::isfinite(v) && std::abs(v) >= lim;
    };
    auto usable = [&](size_t k, int axis) {
      const double v = value(samples[k], gyro, axis);
      return std::isfinite(v) && std::abs(v) < lim;
    };
    for (int axis = 0; axis < 3; ++axis) {
      for (size_t i = 0; i < n;) {
        if (!clipped(i, axis)) {
          ++i;
          continue;
        }
        const double sign = value(samples[i], gyro, axis) > 0.0 ? 1.0 : -1.0;
        size_t j = i;
        while (j + 1 < n && clipped(j + 1, axis) && value(samples[j + 1], gyro, axis) * sign > 0.0) ++j;
        SaturatedRun run;
        run.first = i;
        run.last = j;
        run.gyro = gyro;
        run.axis = axis;
        // The run's duration T = Σ Δt_k (at the log's ends the missing neighbour counts as a repeat of the sample).
        const GpsTime t_before = samples[i > 0 ? i - 1 : i].t, t_after = samples[j + 1 < n ? j + 1 : j].t;
        const double T = 0.5 * ((t_after - samples[i].t) + (samples[j].t - t_before));
        bool ok = T <= o.max_run_s && i >= static_cast<size_t>(nf) && j + nf < n;
        for (int m = 1; ok && m <= nf; ++m) ok = usable(i - m, axis) && usable(j + m, axis);
        if (ok) {
          const GpsTime t0 = samples[i].t;
          // The `count` nearest neighbours on each side of the run (time since its first sample, value).
          auto neighbours = [&](int count, std::vector<double>& t, std::vector<double>& y) {
            for (int m = -count; m <= count; ++m) {
              if (m == 0) continue;
              const ImuSample& x = samples[m < 0 ? i - static_cast<size_t>(-m) : j + static_cast<size_t>(m)];
              t.push_back(x.t - t0);
              y.push_back(value(x, gyro, axis));
            }
          };
          std::vector<double> t4, y4, t2, y2;
          neighbours(nf, t4, y4);
          neighbours(nf - 1, t2, y2);
          const double t_c = 0.5 * (t4.front() + t4.back()), h = std::max(0.5 * (t4.back() - t4.front()), 1e-9);
          const PolyFit p4(t4, y4, 4, t_c, h), p2(t2, y2, 2, t_c, h);
          double added4 = 0.0, added2 = 0.0;
          auto clamp = [&](double v) { return std::min(std::max(sign * v, r), o.max_peak_factor * r); };
          for (size_t k = i; k <= j; ++k) {
            const double tk = samples[k].t - t0;
            const double dtk = 0.5 * (samples[k + 1].t - samples[k - 1].t);
            const double v4 = clamp(p4(tk)), v2 = clamp(p2(tk));
            added4 += (v4 - r) * dtk;
            added2 += (v2 - r) * dtk;
            auto [it, fresh] = repaired.try_emplace(k);
            if (fresh) it->second = {k, samples[k].omega_ib_b, samples[k].f_ib_b};
            (gyro ? it->second.omega_ib_b : it->second.f_ib_b)(axis) = sign * v4;
          }
          run.reconstructed = true;
          run.added = sign * added4;
          run.sigma = std::max(o.sigma_fraction * added4, std::abs(added4 - added2));
          if (!(run.sigma > 0.0)) run.sigma = 0.5 * r * T;
        } else {
          run.sigma = 0.5 * r * T;
        }
        out.runs.push_back(run);
        i = j + 1;
      }
    }
  }
  out.samples.reserve(repaired.size());
  for (auto& [k, s] : repaired) out.samples.push_back(s);
  std::sort(out.runs.begin(), out.runs.end(), [](const SaturatedRun& a, const SaturatedRun& b) {
    return a.last != b.last ? a.last < b.last : (a.gyro != b.gyro ? a.gyro : a.axis < b.axis);
  });
  return out;
}

}  // namespace pednav::ins
