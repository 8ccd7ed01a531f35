// SPDX-License-Identifier: BSD-2-Clause
// GLONASS inter-frequency phase bias between two receiver types (docs/carrier.md §3.1, eqs. 3.9-3.11): the SD phase of
// a GLONASS satellite on frequency channel k carries β k [m] besides its integer ambiguity. Two receivers of one type
// share β (it cancels, `gnss.ambiguity.glonass`); for different types (a u-blox rover on a geodetic reference station)
// it is unknown, constant over a session, and found by searching the β that makes the GLONASS double differences
// integer (`gnss.ambiguity.glonass_ifb: search`). Until it is found GLONASS stays float. No I/O.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "fusion/ambiguity.hpp"

namespace pednav::fusion {

/// GLONASS L1 frequency channel from the signal's wavelength (f = 1602 MHz + k · 0.5625 MHz); 0 when it is not a
/// GLONASS L1 wavelength.
int glonass_channel(double wavelength_m);

/// Float-ambiguity offsets [cycles] of β for the GLONASS candidates (β k / λ at each candidate's state, eq. 3.9),
/// zero at every other state of an n_state vector.
Eigen::VectorXd glonass_ifb_offsets(int n_state, const std::vector<AmbiguityCandidate>& c, double beta_m);

struct GlonassIfbOptions {
  double step_m = 0.0025;   ///< grid step of β [m per channel]
  int votes = 10;           ///< fixes at one β (± one step) before it is taken
  double dominance = 3.0;   ///< ... and this many times the votes of any other β
  int min_glonass = 3;      ///< GLONASS candidates (above the AR mask, locked) an epoch needs to search
};

/// The search of eq. 3.10: at each float epoch, β over one period of the grid (β and β + λ₀ give the same double
/// differences up to integers, λ₀ = c / 1602 MHz), LAMBDA on GPS and GLONASS together at each; the β with the largest
/// ratio gets a vote when its set passes the ratio and success-rate tests; eq. 3.11 takes β when one β (± one step)
/// holds `votes` votes and `dominance` times any other.
class GlonassIfbSearch {
 public:
  explicit GlonassIfbSearch(const GlonassIfbOptions& o = {}) : o_(o) {}
  /// One search step at the float x, P with the candidates as resolution sees them (GLONASS ones are tried as
  /// integers here); returns true when this step took β.
  bool search(const Eigen::VectorXd& x, const Eigen::MatrixXd& P, const std::vector<AmbiguityCandidate>& c,
              const AmbiguityOptions& ar);
  std::optional<double> beta_m() const { return beta_m_; }
  int searches() const { return searches_; }
  int votes_cast() const { return votes_cast_; }

 private:
  GlonassIfbOptions o_;
  std::vector<int> votes_;  ///< per grid index
  std::optional<double> beta_m_;
  int searches_ = 0, votes_cast_ = 0;
};

}  // namespace pednav::fusion
