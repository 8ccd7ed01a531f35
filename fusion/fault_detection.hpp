// SPDX-License-Identifier: BSD-2-Clause
// Fault detection of the GNSS rows of one epoch (docs/fusion.md §6): the iterative Baarda w-test, worst row first,
// against the χ²(1) quantile of the configured probability, and the persistent-fault test over a satellite's
// consecutive epochs (§6.2, eq. 6.5). Each rejection is counted by reason in the summary; a rejected row is data,
// not an error. Internal to the engine.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include "core/time.hpp"
#include "fusion/engine_types.hpp"
#include "gnss/types.hpp"
#include "ins/error_state.hpp"

namespace pednav::fusion {

/// GNSS update rows held in fixed-capacity matrices (32 satellites with code + Doppler); more use dynamic ones.
inline constexpr int kMaxGnssRows = 64;

/// ++m[key] (by n) without constructing a std::string for keys already present (no heap allocation per epoch).
void count_outcome(std::map<std::string, long>& m, const char* key, size_t n = 1);

/// One candidate GNSS measurement row of an epoch with its noise.
struct GnssRow {
  gnss::SatId sat;
  bool doppler = false;
  double residual = 0.0;  ///< measured − predicted [m or m/s]
  ins::ErrorRowVector h;
  double sigma = 0.0;     ///< independent noise [m or m/s]
  /// ∂(predicted)/∂(antenna position) for code rows, ∂/∂(antenna velocity) for Doppler rows: projects the
  /// non-rigid arm's offset / velocity noise common to all satellites into R.
  Eigen::RowVector3d j_antenna = Eigen::RowVector3d::Zero();
};

/// The rows' shared noise: the non-rigid antenna's offset (code rows) and velocity (Doppler rows) covariances, ECEF.
struct CommonAntennaNoise {
  Eigen::Matrix3d position_e;  ///< [m²]
  Eigen::Matrix3d velocity_e;  ///< [m²/s²]
};

/// The w-test of one epoch and the persistent-fault history of each satellite between epochs.
class FaultDetector {
 public:
  /// probability: of the χ²(1) w-test; window_epochs: longest window of the persistent-fault test (< 2: off).
  FaultDetector(double probability, int window_epochs);

  /// The w-test threshold w² (χ²(1) quantile at the configured probability).
  double threshold() const { return w_test_threshold_; }

  /// Iterative w-test of `rows` (all active at the start; `active` holds the indices kept at the end): build H, r,
  /// R of the active rows (n error states), test, reject the worst row above the threshold (single-epoch or
  /// persistent statistic), repeat while more than one row is left. On return H, r, R are those of the kept rows.
  /// Rejections are counted into `sum`; rejected code rows into rejected_code. With `records`, one GnssRowRecord per
  /// row at epoch t is appended (w and MDB of the first test, w_final, rejected).
  template <typename MatH, typename VecR, typename MatR>
  void test(const std::vector<GnssRow>& rows, int n, const CommonAntennaNoise& noise, const ins::ErrorMatrix& P,
            GpsTime t, std::vector<int>& active, std::vector<GnssRowRecord>* records, EngineSummary& sum,
            int& rejected_code, MatH& H, VecR& r, MatR& R);

  /// After the epoch's update: each code row's w in the last test it took part in becomes the newest history entry of
  /// its satellite (a satellite missing from an epoch starts over).
  void record_history(const std::vector<GnssRow>& rows);
  /// Forget every satellite's history (a re-initialization: the diverged filter's innovations are no evidence).
  void clear_history() { fault_history_.clear(); }
  /// Capacity for kMaxGnssRows satellites (no allocation on the per-epoch path).
  void reserve() { fault_history_.reserve(static_cast<size_t>(kMaxGnssRows)); }

 private:
  // One satellite's code w of its last consecutive GNSS epochs.
  struct FaultHistory {
    gnss::SatId sat;
    long epoch = -1;  // the GNSS epoch count at the newest entry
    int count = 0;    // valid entries in w (newest first)
    std::array<double, kMaxFaultWindowEpochs - 1> w{};
  };
  double persistent_fault_statistic(const gnss::SatId& sat, double w) const;
  FaultHistory& history_slot(const gnss::SatId& sat);
  template <typename MatH, typename VecR, typename MatR>
  static void build(const std::vector<GnssRow>& rows, const std::vector<int>& active, int n,
                    const CommonAntennaNoise& noise, MatH& H, VecR& r, MatR& R);

  const int window_epochs_;
  const double w_test_threshold_;  // computed once (a bisection on the incomplete gamma function), not per epoch
  std::vector<double> w_last_;     // per row of the epoch: w in the last test it took part in
  std::vector<FaultHistory> fault_history_;  // at most kMaxGnssRows satellites, reserved once
  long gnss_epoch_ = 0;                      // GNSS epochs that reached the w-test
};

template <typename MatH, typename VecR, typename MatR>
void FaultDetector::build(const std::vector<GnssRow>& rows, const std::vector<int>& active, int n,
                          const CommonAntennaNoise& noise, MatH& H, VecR& r, MatR& R) {
  const int m = static_cast<int>(active.size());
  H.resize(m, n);
  r.resize(m);
  R.setZero(m, m);
  for (int i = 0; i < m; ++i) {
    const GnssRow& a = rows[active[i]];
    H.row(i) = a.h;
    r(i) = a.residual;
    R(i, i) = a.sigma * a.sigma;
  }
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      const GnssRow& a = rows[active[i]];
      const GnssRow& b = rows[active[j]];
      if (a.doppler == b.doppler) {
        R(i, j) += a.j_antenna * (a.doppler ? noise.velocity_e : noise.position_e) * b.j_antenna.transpose();
      }
    }
  }
}

template <typename MatH, typename VecR, typename MatR>
void FaultDetector::test(const std::vector<GnssRow>& rows, int n, const CommonAntennaNoise& noise,
                         const ins::ErrorMatrix& P, GpsTime t, std::vector<int>& active,
                         std::vector<GnssRowRecord>* records, EngineSummary& sum, int& rejected_code, MatH& H,
                         VecR& r, MatR& R) {
  // w-test fault rejection, worst first (Baarda): w_i = (S^-1 nu)_i / sqrt((S^-1)_ii) against chi2(1, p).
  using SMatrix = MatR;
  using RVector = VecR;
  const double threshold = w_test_threshold_;
  active.resize(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) active[i] = static_cast<int>(i);
  w_last_.assign(rows.size(), 0.0);
  const size_t first_record = records ? records->size() : 0;
  bool first_test = true;
  for (;;) {
    build(rows, active, n, noise, H, r, R);
    SMatrix S = R;
    S.noalias() += H * P * H.transpose();
    const SMatrix Sinv = S.ldlt().solve(SMatrix::Identity(S.rows(), S.cols()));
    const RVector a = Sinv * r;
    if (records && first_test) {
      // Baarda's internal reliability: MDB_i = (k + z_0.8) / sqrt((S^-1)_ii), k = sqrt(threshold) (docs/fusion.md eq. 6.4).
      constexpr double kZPower80 = 0.8416;
      const double sqrt_lambda = std::sqrt(threshold) + kZPower80;
      for (int i = 0; i < a.size(); ++i) {
        const GnssRow& row = rows[active[i]];
        GnssRowRecord rec;
        rec.t = t;
        rec.sat = row.sat;
        rec.doppler = row.doppler;
        rec.innovation = row.residual;
        rec.sigma = row.sigma;
        rec.w = a(i) / std::sqrt(Sinv(i, i));
        rec.mdb = sqrt_lambda / std::sqrt(Sinv(i, i));
        records->push_back(rec);
      }
    }
    first_test = false;
    int worst = -1;
    double worst_w2 = threshold;
    bool worst_persistent = false;
    for (int i = 0; i < a.size(); ++i) {
      const double w = a(i) / std::sqrt(Sinv(i, i));
      w_last_[static_cast<size_t>(active[i])] = w;
      if (records) (*records)[first_record + static_cast<size_t>(active[i])].w_final = w;
      const double w2 = w * w;
      if (w2 > worst_w2) {
        worst_w2 = w2;
        worst = i;
        worst_persistent = false;
      }
      if (const GnssRow& row = rows[active[i]]; !row.doppler) {
        const double g2 = persistent_fault_statistic(row.sat, w);
        if (g2 > worst_w2) {
          worst_w2 = g2;
          worst = i;
          worst_persistent = true;
        }
      }
    }
    if (worst < 0 || active.size() <= 1) break;
    const GnssRow& bad = rows[active[worst]];
    if (records) (*records)[first_record + static_cast<size_t>(active[worst])].rejected = true;
    if (bad.doppler) {
      count_outcome(sum.doppler_used_rejected, "innovation_fault");
    } else {
      count_outcome(sum.code_used_rejected, worst_persistent ? "persistent_fault" : "innovation_fault");
      ++rejected_code;
    }
    active.erase(active.begin() + worst);
  }
}

}  // namespace pednav::fusion
