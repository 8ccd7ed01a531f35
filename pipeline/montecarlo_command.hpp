// SPDX-License-Identifier: BSD-2-Clause
// `pednav montecarlo SCENARIO.yaml --runs N -o OUT`: N seeded simulate + run pairs (issue 9, seed 000), in parallel
// on all cores. Each run is simulated in memory (sim::simulate) and processed by the engine in memory
// (fusion::run_forward): no RTKLIB call is made, so the runs are independent and thread-safe. Each finished run is
// written atomically to OUT/runs/run_NNNN.csv; a run whose file exists is not redone (resumable). Then the runs
// are aggregated by eval/montecarlo (per-epoch mean error, sample σ, filter σ, NEES with its 95 % band, error vs
// distance) into runs.csv, nees.csv and summary.json. docs/consistency.md.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "fusion/step_velocity.hpp"

namespace pednav::pipeline {

/// What `pednav montecarlo` was asked for (apps/cmd_montecarlo.cpp maps the flags onto it).
struct MontecarloArgs {
  std::string scenario_path;
  std::string out_dir;
  int runs = 100;
  int jobs = 0;                 ///< 0: all hardware threads
  std::string mode;             ///< tc | ins (empty: tc when the scenario simulates GNSS, else ins)
  std::string zupt_form = "D";
  bool smoother = true;
  uint64_t seed_offset = 0;     ///< run i uses scenario.seed + seed_offset + i
  double summary_from_s = -1e300;  ///< summary over epochs with t >= this [s since the scenario start]
  bool zupt_updates = true;        ///< false: the detector only segments steps
  bool step_velocity = false;      ///< seed 000 step-velocity aiding
  double leg_length_m = fusion::StepVelocityOptions{}.leg_length_m;
  bool multipath_states = false;   ///< filter multipath GM states with the scenario's multipath model
  bool white_code = false;         ///< no multipath states (white code errors in R)
  bool scale_states = false;       ///< filter scale-factor states (the scenario's IMU spec)
  bool accel_scale_states = false; ///< filter accelerometer scale-factor states only
  bool bias_random_walk = false;   ///< filter bias model: turn-on constant + random walk (`bias: {model: random_walk}`)
  bool no_scale_states = false;    ///< no scale-factor states (the mode-ins default; tc has accelerometer ones)
  bool gauss_markov_bias = false;  ///< Gauss-Markov bias model (the mode-ins default; tc uses the random walk)
  bool saturation_repair = true;   ///< reconstruct clipped IMU runs (`saturation: {repair: false}` to switch off)
  bool no_doppler = false;             ///< no Doppler rows (`gnss: {use_doppler: false}`)
  bool foot_antenna_velocity = false;  ///< Doppler rows with the foot's own velocity (`antenna: {velocity_model: foot}`)
  std::optional<bool> scale_bias_compensation;  ///< scale_factors.bias_compensation (unset: the default)
  std::optional<bool> smoother_eiv_regression;  ///< EngineOptions::smoother_eiv_regression (unset: the default)
  double elevation_weight = std::numeric_limits<double>::quiet_NaN();  ///< gnss.elevation_weight (NaN: the default)
  bool scenario_lever_arm = false;  ///< antenna lever arm from the scenario's walker geometry (docs/fusion.md §14)
  bool g_sensitivity_states = false;  ///< filter g-sensitivity states with the scenario's σ (docs/error_state.md §5)
  double window_s = 150.0;         ///< summary.json windows_*: the band test per window of this length [s]
  bool plots = true;               ///< nees.svg, sigma.svg, sigma_yaw.svg, error_vs_distance.svg
  bool receiver_weights = false;   ///< code/Doppler weights from the scenario's receiver model (docs/consistency.md §3.8)
  /// L1 carrier phase in the tight coupling (`gnss.carrier: on`, antenna states; the scenario must simulate
  /// `gnss.carrier_phase`): runs.csv and summary.json add the fix rate, wrong fixes and the fixed antenna's NEES.
  bool carrier = false;
  /// --shard K/N: only runs i with i mod N = K − 1, into out_dir/runs/ with out_dir/shard.json (no statistics);
  /// run_montecarlo_merge combines the N folders into what one process gives.
  int shard_index = 1;
  int shard_count = 1;
};

/// Runs the study into args.out_dir (resumable: existing runs/run_NNNN.csv are read, not redone); logs progress and
/// the summary line; fails with the message of the first problem (scenario, output folder, a run file, < 2 runs).
Expected<void> run_montecarlo_command(const MontecarloArgs& args);

/// `pednav montecarlo-merge OUT SHARD_DIR...`: the shards of one study (same scenario text and options, every shard
/// 1..N exactly once) → OUT/runs/, runs.csv, nees.csv, summary.json and (with plots) the figures, exactly as one
/// process writes them except the wall-clock fields. Errors name the missing, duplicated or foreign shard.
Expected<void> run_montecarlo_merge(const std::string& out_dir, const std::vector<std::string>& shard_dirs, bool plots);

}  // namespace pednav::pipeline
