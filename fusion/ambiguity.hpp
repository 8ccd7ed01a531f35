// SPDX-License-Identifier: BSD-2-Clause
// Integer ambiguity resolution on the SD ambiguity states of a filter (docs/carrier.md §3): the double differences
// of each constellation against its highest satellite, LAMBDA with the ratio test and the bootstrapped success
// rate, partial resolution (the lowest satellites dropped one by one while the full set fails), and the conditioning
// of the float state on the accepted integers (eq. 3.6). Shared by the GNSS-only RTK filter and the tight coupling.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/geodesy.hpp"
#include "gnss/types.hpp"

namespace pednav::fusion {

/// Solution status of an epoch (solution.csv `solution_status`, .pos Q: 1 fixed, 2 float, 5 code).
enum class SolutionStatus : int { kNone = 0, kFixed, kFloat, kCode, kIns };
const char* solution_status_name(SolutionStatus s);
/// RTKLIB .pos Q of a status (1 fixed, 2 float, 5 code, single or INS-only; 0 none).
int pos_quality(SolutionStatus s);

/// Ambiguity-resolution options (config `gnss.ambiguity`, docs/carrier.md §3).
struct AmbiguityOptions {
  double ratio_threshold = 3.0;          ///< second-best / best squared norm must reach this
  double min_success_rate = 0.999;       ///< bootstrapped success rate of the decorrelated set (eq. 3.4)
  double ar_elevation_mask_rad = 15.0 * kDegToRad;  ///< satellites below take part as float only
  bool partial = true;                   ///< drop the lowest satellites while the full set fails
  int min_ambiguities = 6;               ///< fewest double differences in a fix
  int min_lock_epochs = 3;               ///< epochs an ambiguity must have been tracked before it is fixed
  bool hold = false;                     ///< fix-and-hold: validated fixes constrain the float filter
  int hold_min_epochs = 5;               ///< consecutive validated fixes of the same integers before a hold
  double hold_sigma_cycles = 0.01;       ///< σ of a held double difference [cycles]
  double validation_w = 4.0;             ///< |w| of a fixed-solution phase residual beyond this rejects the fix
  /// GLONASS SD ambiguities [cycles of each channel] are resolved as integers too: valid when the rover and the base
  /// are receivers of one type (their inter-frequency phase biases cancel), RTKLIB's `pos2-gloarmode = on`.
  bool glonass = false;
  /// GLONASS integers for any receiver pair: the inter-frequency phase bias rate β is searched (eqs. 3.9-3.11,
  /// fusion/glonass_ifb; 0 for two receivers of one type) and, once found, removed before GLONASS is resolved as
  /// integers. `pednav gnss` only (the tight coupling keeps GLONASS float unless `glonass`).
  bool glonass_ifb_search = true;
};

/// One SD ambiguity state offered for resolution.
struct AmbiguityCandidate {
  int state = -1;                ///< index in the filter's state vector (cycles)
  gnss::SatId sat;
  double elevation_rad = 0.0;
  int lock_epochs = 0;           ///< epochs since the ambiguity was (re)started
  bool integer = true;           ///< integer-capable (not GLONASS, no half-cycle flag)
  double wavelength_m = 0.0;     ///< the signal's (GLONASS: its frequency channel, eq. 3.9); 0 = unknown
};

/// The outcome of one resolution attempt.
struct AmbiguityFix {
  bool fixed = false;
  double ratio = 0.0;           ///< of the accepted set, or of the full set when none was accepted
  double success_rate = 0.0;
  Eigen::MatrixXd D;            ///< double-difference operator over the full state (one row per fixed DD)
  Eigen::VectorXd z;            ///< the integers [cycles]
  std::vector<gnss::SatId> sats;///< satellites whose ambiguity is in a fixed DD (references included)
  int n_candidates = 0;         ///< double differences offered
  std::string why_not;          ///< empty when fixed
};

/// Resolve the candidates' double differences from the float state x and covariance P (docs/carrier.md eqs. 3.1-3.5).
AmbiguityFix resolve_ambiguities(const Eigen::VectorXd& x, const Eigen::MatrixXd& P,
                                 const std::vector<AmbiguityCandidate>& candidates, const AmbiguityOptions& o);

/// Condition x and P on D x = z with noise σ [cycles] per row (σ = 0: the exact conditional, eq. 3.6):
/// K = P Dᵀ (D P Dᵀ + σ² I)⁻¹, x += K (z − D x), P = (I − K D) P (I − K D)ᵀ + K σ² Kᵀ.
/// Returns false (x, P unchanged) when D P Dᵀ + σ² I is singular.
bool condition_on_integers(Eigen::VectorXd& x, Eigen::MatrixXd& P, const Eigen::MatrixXd& D, const Eigen::VectorXd& z,
                           double sigma_cycles);

}  // namespace pednav::fusion
