// SPDX-License-Identifier: BSD-2-Clause
// Discrete hidden Markov model of the gait cycle (seed 002 §3): 4 states (push-off A, swing B, heel strike C,
// stance D), 15 observation symbols (quantized extreme values of the gyro rate about the axis across the foot),
// scaled forward-backward, Baum-Welch re-estimation (seed 002 eq. 3-4, discrete form of eq. 5-7; Rabiner 1989
// §V.A scaling), Viterbi and forward (filtering) decoding, and the observation extraction of seed 002 §3.3
// (Fig. 5). How decoded states on extreme values are mapped back to sample time: docs/zupt.md §3.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ins/imu.hpp"

namespace pednav::ins {

inline constexpr int kHmmStates = 4;    ///< N: A push-off, B swing, C heel strike, D stance (seed 002 §3.1)
inline constexpr int kHmmSymbols = 15;  ///< M: grades 1..15, stored 0-based (symbol k = grade k+1)

/// State indices (0-based rows/columns of A and B).
enum GaitState : int { kPushOff = 0, kSwing = 1, kHeelStrike = 2, kStance = 3 };

/// Letter of a gait state index ('A'..'D'), '-' for anything else.
char gait_state_letter(int state);

/// λ = (A, B, π) of a discrete HMM.
struct HmmModel {
  Eigen::Matrix4d A;                                   ///< a_ij = P(q_{t+1} = j | q_t = i), rows sum to 1
  Eigen::Matrix<double, kHmmStates, kHmmSymbols> B;    ///< b_j(k) = P(o_t = k | q_t = j), rows sum to 1
  Eigen::Vector4d pi;                                  ///< π_i = P(q_1 = i), sums to 1
  /// Every problem at once (negative, non-finite or non-normalized rows), empty when valid.
  std::vector<std::string> problems() const;
};

/// Seed 002's initial model: A₁ (§3.2) and the observation probabilities of Table 1 (columns = states, in %).
/// Table 1 has zeros, which Baum-Welch can never leave; every entry is raised to at least `floor` and the rows
/// renormalized (floor 0 keeps the zeros; the printed columns sum to 99.97-101.54 %, so every row is renormalized).
/// π is uniform.
HmmModel seed002_initial_model(double floor = 1e-3);

/// One observation: a run of consecutive extreme values of the smoothed rate that fall in the same grade
/// (seed 002 §3.3: redundant consecutive extremes merged).
struct GaitObservation {
  int symbol = 0;       ///< grade - 1, 0..14
  std::size_t first = 0;  ///< sample index of the first extreme of the run
  std::size_t last = 0;   ///< sample index of the last extreme of the run
  double rate_radps = 0;  ///< smoothed rate at `first` [rad/s] (axis and sign of HmmObservationOptions)
};

/// Options of the observation extraction (seed 002 §3.3, Fig. 5).
struct HmmObservationOptions {
  int axis = 1;                 ///< gyro axis across the foot: 0 x, 1 y, 2 z of the IMU body frame
  double sign = 1.0;            ///< +1 or -1 so that push-off is negative and swing positive (as in seed 002 Fig. 2e)
  double smooth_window_s = 0.05;    ///< moving-average window (centred) [s]
  double grade_width_radps = 1.05;  ///< width of one grade [rad/s]; grade 8 = [-w, 0), 9 = [0, w), 1 and 15 open
  double min_prominence_grades = 0.5;  ///< an extreme counts once the rate moved this many grades away from it
  /// Every problem at once, empty when valid.
  std::vector<std::string> problems() const;
};

/// The extracted observation sequence of one log, with the per-sample signal it came from.
struct GaitObservations {
  std::vector<double> rate_radps;   ///< smoothed signed rate per sample [rad/s]
  std::vector<int> grade;           ///< per-sample quantized grade - 1 (0..14)
  std::vector<GaitObservation> obs; ///< observation sequence (extremes, merged), time-ordered
  std::vector<int> symbols() const; ///< obs[k].symbol
};

/// Grade (0-based symbol) of a rate [rad/s]: 8 + floor(rate / width), clamped to 0..14, so zero rate is the
/// boundary of grades 8 and 9, the two grades seed 002's stance state emits (Table 1: 85 %; docs/zupt.md §2).
int quantize_rate(double rate_radps, double grade_width_radps);

/// Observation extraction of seed 002 §3.3 over time-ordered samples (any rate): signed rate of the chosen
/// axis -> centred moving average -> local extremes with a minimum prominence (the first sample counts as an
/// extreme) -> quantization into 15 grades -> runs of consecutive extremes in the same grade merged into one
/// observation.
GaitObservations extract_gait_observations(const std::vector<ImuSample>& samples, const HmmObservationOptions& options);

/// Scaled forward-backward (Rabiner 1989 eq. 91-93) of one sequence.
struct ForwardBackward {
  double log_likelihood = 0.0;              ///< ln P(O | λ) = -Σ ln c_t
  std::vector<Eigen::Vector4d> alpha_hat;   ///< scaled forward variables (each sums to 1)
  std::vector<Eigen::Vector4d> gamma;       ///< posterior state probabilities γ_t(i)
};

/// Forward-backward of `symbols` (0..14) under `model`; log_likelihood = -inf when the sequence is impossible.
ForwardBackward forward_backward(const HmmModel& model, const std::vector<int>& symbols);

/// Options of Baum-Welch training.
struct BaumWelchOptions {
  int max_iterations = 200;
  double tolerance = 1e-7;   ///< stop when the log-likelihood gain per observation falls below this
  bool update_pi = true;     ///< re-estimate π (seed 002 eq. 4); false keeps the initial π
};

/// Result of Baum-Welch training.
struct BaumWelchResult {
  HmmModel model;                       ///< trained λ
  std::vector<double> log_likelihood;   ///< ln P(O | λ_n) of each iterate n = 0 (initial) .. final, summed over sequences
  int iterations = 0;                   ///< re-estimations done
  bool converged = false;               ///< tolerance reached before max_iterations
  long observations = 0;                ///< symbols used, all sequences
};

/// Baum-Welch (EM) over several independent sequences (numerators and denominators of seed 002 eq. 3-4 and of
/// the discrete b_j(k) re-estimate summed over sequences; Rabiner 1989 eq. 109-110). Pure EM: no flooring after
/// the initial model, so ln P(O | λ) never decreases (up to rounding). Sequences shorter than 2 are skipped.
BaumWelchResult baum_welch(const HmmModel& initial, const std::vector<std::vector<int>>& sequences,
                           const BaumWelchOptions& options = {});

/// Most likely state sequence (Viterbi, log domain). Empty input -> empty output.
std::vector<int> viterbi(const HmmModel& model, const std::vector<int>& symbols);

/// Online decoding: argmax of the filtered posterior P(q_t | o_1..o_t) (normalized forward variables).
std::vector<int> forward_decode(const HmmModel& model, const std::vector<int>& symbols);

/// A model with every B and A entry raised to at least `floor` and rows renormalized (for decoding data that
/// contains symbols a trained model never saw).
HmmModel floored(const HmmModel& model, double floor);

/// Draw a state and symbol sequence of `length` from `model` with a fixed-seed generator (tests, studies).
struct HmmDraw {
  std::vector<int> states;
  std::vector<int> symbols;
};
HmmDraw draw_hmm_sequence(const HmmModel& model, int length, std::uint64_t seed);

/// Map states decoded on the observations back to samples (docs/zupt.md §3): the state of observation n holds
/// on its dwell (the run of samples around its extremes whose grade equals its symbol, bounded by the
/// neighbouring observations' extremes; for a stance (D) observation also grades flagged in `stance_grades`);
/// samples between two dwells take the state of the next observation, except before a stance observation, where
/// they keep the previous state (stance only while the signal stays in a stance grade). One state per sample.
std::vector<int> states_per_sample(const GaitObservations& observations, const std::vector<int>& obs_states,
                                   const std::array<bool, kHmmSymbols>& stance_grades = {});

/// Grades the stance state D of `model` emits with probability >= min_probability (b_D(k) >= p), and always
/// grades 8 and 9 (zero rate is their boundary, so the rate at rest alternates between them).
std::array<bool, kHmmSymbols> stance_grades(const HmmModel& model, double min_probability);

}  // namespace pednav::ins
