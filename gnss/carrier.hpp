// SPDX-License-Identifier: BSD-2-Clause
// L1 carrier phase: the single-differenced (rover − base) phase model with its Jacobian, the cycle-slip tests that
// need no state estimate (loss-of-lock and half-cycle flags, phase against integrated Doppler), and the
// double-difference transform of SD ambiguities used for integer resolution. Shared by the GNSS-only RTK filter and
// the tightly coupled filter (fusion/). Model, signs and equations: docs/carrier.md.
#pragma once

#include <Eigen/Core>
#include <array>
#include <optional>
#include <vector>

#include "core/time.hpp"
#include "gnss/measurement.hpp"
#include "gnss/types.hpp"

namespace pednav::gnss {

/// RINEX loss-of-lock indicator bits (RINEX 3.04 §5.7): bit 0 loss of lock since the previous epoch (a possible
/// slip), bit 1 half-cycle ambiguity not resolved (the phase may be off by half a cycle).
inline constexpr uint8_t kLliSlip = 0x01;
inline constexpr uint8_t kLliHalfCycle = 0x02;

/// Whether a constellation's SD ambiguities are resolved as integers. GLONASS (FDMA: one wavelength per channel)
/// keeps them float: its double differences are not integers without the inter-frequency bias (docs/carrier.md §1).
bool integer_ambiguity_system(System s);

/// Single-differenced carrier phase in metres (docs/carrier.md eq. 1.1):
/// λ(Φ_r − Φ_b) = ρ_r − ρ_b − c(dt_s(t_tx,r) − dt_s(t_tx,b)) + c dt_rb + λ N_rb + ε. The model is the SD code
/// model (gnss/measurement.hpp sd_pseudorange) with the phase ranges λΦ in place of the code; the ambiguity term
/// λ N_rb is the caller's (its Jacobian w.r.t. N_rb [cycles] is λ). `rover`/`base` carry λΦ [m] in pseudorange_m.
/// Residual = measured − predicted without λ N_rb; J_p w.r.t. the rover antenna p_ea_e [m, ECEF]; J_clock = 1.
MeasurementRow sd_carrier_phase(SatId sat, const SignalAtReceiver& rover, const SignalAtReceiver& base,
                                const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& p_eb_e, double clock_rb_m);

/// Time-differenced carrier phase of one satellite between two epochs of the same receiver and the same phase arc
/// (docs/carrier.md eq. 9.1): λΦ_k − λΦ_j = ρ_k(p_k) − ρ_j(p_j) − c(dt_s,k − dt_s,j) + Δ(c dt_r) + ε; the ambiguity
/// cancels, the atmosphere's change over the interval is left out (eq. 9.2). `now`/`prev` carry λΦ [m] in
/// pseudorange_m and the satellite state at each epoch's transmit time. Residual = measured − predicted;
/// J_p w.r.t. p_now [m, ECEF], J_v holds the Jacobian w.r.t. p_prev (the cloned antenna position), J_clock = 1 is
/// w.r.t. the receiver clock change Δ(c dt_r) [m].
MeasurementRow td_carrier_phase(SatId sat, const SignalAtReceiver& now, const SignalAtReceiver& prev,
                                const Eigen::Vector3d& p_now_e, const Eigen::Vector3d& p_prev_e, double clock_change_m);

/// Carrier-phase noise σ [m] of one receiver (docs/carrier.md eq. 1.3): the code weight model's C/N0 and elevation
/// factors (docs/gnss.md eq. W1) applied to the zenith phase σ.
double carrier_sigma_m(const WeightModel& model, double carrier_sigma_zenith_m, double cn0_dbhz, double elevation_rad);

/// Why a satellite's ambiguity was restarted (summary.json `carrier.slips`).
enum class SlipReason : int {
  kLossOfLock = 0,   ///< LLI bit 0
  kHalfCycle,        ///< LLI bit 1 appeared or cleared (the phase moved by half a cycle, or may have)
  kDoppler,          ///< phase change against integrated Doppler (eq. 2.1)
  kGeometry,         ///< phase innovation against the predicted SD geometry (the filter's w-test, eq. 2.2)
  kGap,              ///< no phase for longer than the maximum gap
  kWrongFix,         ///< the ambiguity took part in a fix that failed validation after it was held
  kCount
};
const char* slip_reason_name(SlipReason r);

/// The last phase of one satellite at one receiver (for the Doppler test).
struct PhaseHistory {
  GpsTime t;
  double phase_cycles = kNaN;
  double doppler_hz = kNaN;
  bool half_cycle = false;
};

struct DopplerSlipOptions {
  double threshold_cycles = 3.0;     ///< |ΔΦ − predicted| beyond this [cycles] + the growth term below is a slip
  double threshold_per_s_cycles = 1.0;  ///< the threshold grows with the epoch interval [cycles/s]
  double max_gap_s = 10.0;           ///< longer gaps restart the ambiguity
};

/// Per-epoch slip screening of one receiver's phases without a state estimate (docs/carrier.md §2): LLI bits, gap,
/// and phase against integrated Doppler, ΔΦ ≈ −½(D_prev + D_now) Δt (eq. 2.1). A common jump of every satellite
/// (receiver clock steering) is removed first by the median of the differences. `history` is indexed like `ids`
/// and updated; the returned vector holds, for each satellite of `epoch` (by position), the slip reason or none.
class PhaseSlipScreen {
 public:
  explicit PhaseSlipScreen(DopplerSlipOptions o = {}) : o_(o) {}
  std::vector<std::optional<SlipReason>> screen(const ObsEpoch& epoch);
  /// Forget a satellite (its next phase starts a new arc without a slip being counted).
  void forget(SatId sat);

 private:
  DopplerSlipOptions o_;
  std::vector<std::pair<SatId, PhaseHistory>> history_;
  std::vector<double> diffs_;
};

/// The between-satellite difference operator of one group: rows e_i − e_ref for every member i ≠ ref (docs/carrier.md
/// eq. 3.1). members: column indices of the group's SD ambiguities within a vector of length n; ref_pos: position
/// of the reference within members.
Eigen::MatrixXd double_difference_operator(const std::vector<int>& members, int ref_pos, int n);

}  // namespace pednav::gnss
