// SPDX-License-Identifier: BSD-2-Clause
// Fault detection of the GNSS rows (fusion/fault_detection.hpp): the persistent-fault history per satellite.
#include "fusion/fault_detection.hpp"

#include <algorithm>

#include "gnss/least_squares.hpp"

namespace pednav::fusion {

void count_outcome(std::map<std::string, long>& m, const char* key, size_t n) {
  for (auto& [k, v] : m) {
    if (k == key) {
      v += static_cast<long>(n);
      return;
    }
  }
  m[key] += static_cast<long>(n);
}

FaultDetector::FaultDetector(double probability, int window_epochs)
    : window_epochs_(window_epochs), w_test_threshold_(gnss::chi_square_quantile(probability, 1)) {}

// Persistent-fault statistic of a code row with w-statistic `w` (docs/fusion.md eq. 6.5): the largest
// (Σ w)² / n over the windows of n = 2..N consecutive epochs that end with this one, the earlier terms from the
// satellite's history (each clipped to the single-epoch threshold k, so a blunder the single test already caught
// cannot carry the next epochs). Only when |w| ≥ 1 and the window sum has the sign of w: the fault must show in this
// epoch too. 0 when the test is off or the satellite has no history from the previous epoch.
double FaultDetector::persistent_fault_statistic(const gnss::SatId& sat, double w) const {
  if (window_epochs_ < 2 || std::abs(w) < 1.0) return 0.0;
  const auto it = std::find_if(fault_history_.begin(), fault_history_.end(),
                               [&](const FaultHistory& e) { return e.sat == sat; });
  if (it == fault_history_.end() || it->epoch != gnss_epoch_ - 1) return 0.0;
  const FaultHistory& h = *it;
  const double k = std::sqrt(w_test_threshold_);
  double sum_w = w, best = 0.0;
  for (int j = 0; j < h.count && j + 2 <= window_epochs_; ++j) {
    sum_w += std::clamp(h.w[static_cast<size_t>(j)], -k, k);
    if (sum_w * w > 0.0) best = std::max(best, sum_w * sum_w / (j + 2));
  }
  return best;
}

void FaultDetector::record_history(const std::vector<GnssRow>& rows) {
  if (window_epochs_ >= 2) {
    for (size_t i = 0; i < rows.size(); ++i) {
      if (rows[i].doppler) continue;
      FaultHistory& h = history_slot(rows[i].sat);
      if (h.epoch != gnss_epoch_ - 1) h.count = 0;
      const int keep = std::min(h.count, window_epochs_ - 2);
      for (int j = keep; j > 0; --j) h.w[static_cast<size_t>(j)] = h.w[static_cast<size_t>(j - 1)];
      h.w[0] = w_last_[i];
      h.count = keep + 1;
      h.epoch = gnss_epoch_;
    }
  }
  ++gnss_epoch_;
}

// The history entry of `sat`: its own, else a new one, else the one not updated for longest (a set satellite).
FaultDetector::FaultHistory& FaultDetector::history_slot(const gnss::SatId& sat) {
  auto it = std::find_if(fault_history_.begin(), fault_history_.end(),
                         [&](const FaultHistory& e) { return e.sat == sat; });
  if (it != fault_history_.end()) return *it;
  if (fault_history_.size() < static_cast<size_t>(kMaxGnssRows)) {
    fault_history_.push_back(FaultHistory{});
    it = fault_history_.end() - 1;
  } else {
    it = std::min_element(fault_history_.begin(), fault_history_.end(),
                          [](const FaultHistory& a, const FaultHistory& b) { return a.epoch < b.epoch; });
    *it = FaultHistory{};
  }
  it->sat = sat;
  return *it;
}

}  // namespace pednav::fusion
