// SPDX-License-Identifier: BSD-2-Clause
// `pednav montecarlo SCENARIO.yaml --runs N -o OUT`: the flags; the study is pipeline/montecarlo_command.
#include <spdlog/spdlog.h>

#include <sstream>

#include "apps/commands.hpp"
#include "pipeline/montecarlo_command.hpp"

namespace pednav::apps {

void add_montecarlo_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("montecarlo", "N seeded simulate + run pairs in parallel: NEES, sample vs filter sigma");
  auto mo = std::make_shared<pipeline::MontecarloArgs>();
  cmd->add_option("SCENARIO", mo->scenario_path, "Scenario file (YAML, as for pednav simulate)")->required();
  cmd->add_option("-o,--output", mo->out_dir, "Output folder (runs/, runs.csv, nees.csv, summary.json, *.svg)")->required();
  cmd->add_option("--runs", mo->runs, "Number of runs (seeds scenario.seed + i)")->check(CLI::Range(2, 100000));
  cmd->add_option("--jobs", mo->jobs, "Parallel runs (default: all hardware threads)")->check(CLI::Range(0, 256));
  cmd->add_option("--mode", mo->mode, "tc | ins (default: tc if the scenario simulates GNSS, else ins)")
      ->check(CLI::IsMember({"tc", "ins"}));
  cmd->add_option("--zupt-form", mo->zupt_form, "ZUPT form D | F (seed 001)")->check(CLI::IsMember({"D", "F"}));
  cmd->add_option("--seed-offset", mo->seed_offset, "Run i uses seed scenario.seed + offset + i");
  cmd->add_option("--summary-from-s", mo->summary_from_s, "Summarize epochs from this time since the scenario start [s]");
  cmd->add_flag("!--no-smoother", mo->smoother, "Forward filter only");
  cmd->add_option("--window-s", mo->window_s,
                  "Window length of summary.json's windows_forward/windows_smoothed (NEES in band per window) [s]")
      ->check(CLI::Range(1.0, 1e6));
  cmd->add_flag("!--no-plots", mo->plots,
                "No SVG figures (nees.svg, sigma.svg, sigma_yaw.svg, error_vs_distance.svg: seed 000 Figs. 4-6)");
  cmd->add_flag("!--no-zupt-updates", mo->zupt_updates, "The ZUPT detector only segments steps (no ZUPT updates)");
  cmd->add_flag("--multipath-states", mo->multipath_states,
                "Filter code-multipath Gauss-Markov states with the scenario's multipath sigma/tau/C/N0 reference (none if "
                "its sigma is under 1 mm, the run configuration's minimum)");
  cmd->add_flag("--white-code", mo->white_code,
                "No multipath states (white code errors; `multipath: {states: false}` of pednav run)")
      ->excludes("--multipath-states");
  cmd->add_flag("--scale-states", mo->scale_states, "Filter gyro/accelerometer scale-factor states");
  cmd->add_flag("--accel-scale-states", mo->accel_scale_states,
                "Filter accelerometer scale-factor states only (`scale_factors: {states: true, gyro: false}`)")
      ->excludes("--scale-states");
  cmd->add_flag("--bias-random-walk", mo->bias_random_walk,
                "Filter bias model: turn-on bias constant + random walk (`bias: {model: random_walk}`; tc default)");
  cmd->add_flag("--no-scale-states", mo->no_scale_states,
                "No scale-factor states (`scale_factors: {states: false}`; mode tc has both blocks by default)")
      ->excludes("--scale-states")
      ->excludes("--accel-scale-states");
  cmd->add_flag("--gauss-markov-bias", mo->gauss_markov_bias,
                "Filter bias model: one Gauss-Markov state per axis (`bias: {model: gauss_markov}`; mode ins default)")
      ->excludes("--bias-random-walk");
  cmd->add_flag("!--no-saturation-repair", mo->saturation_repair,
                "Integrate clipped IMU samples as they are (`saturation: {repair: false}`)");
  cmd->add_flag("--carrier", mo->carrier,
                "L1 carrier phase in the tight coupling (`gnss: {carrier: on}`, antenna states; the scenario must set "
                "gnss.carrier_phase): runs.csv and summary.json add the fix rate, wrong fixes (antenna > 0.10 m off) and "
                "the fixed antenna's NEES (docs/consistency.md §6)");
  cmd->add_flag("--no-doppler", mo->no_doppler, "Code rows only, no Doppler rows (`gnss: {use_doppler: false}`)");
  cmd->add_flag("--foot-antenna-velocity", mo->foot_antenna_velocity,
                "Doppler rows predict the antenna velocity as the foot's own (`antenna: {velocity_model: foot}`; "
                "default: the stride-average foot velocity)");
  cmd->add_option("--elevation-weight", mo->elevation_weight,
                  "k of the code/Doppler weight's elevation factor (gnss.elevation_weight, default 1; docs/gnss.md eq. W1)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--receiver-weights", mo->receiver_weights,
                "Code/Doppler weights (with --carrier also the phase sigma) from the scenario's receiver model (DLL thermal noise at its zenith C/N0, no "
                "elevation factor unless --elevation-weight; docs/consistency.md §3.8) instead of pednav run's defaults");
  cmd->add_flag("--scenario-lever-arm", mo->scenario_lever_arm,
                "Antenna lever arm from the scenario's walker: antenna height above the foot IMU (NED) and the IMU foot "
                "beside the walking line (antenna.lever_arm_heading_m = [0, -gait.foot_offset_m, 0]; docs/fusion.md §14) "
                "instead of pednav run's default [0, 0, -1.2] m");
  cmd->add_flag("--g-sensitivity-states", mo->g_sensitivity_states,
                "The gyro's g-sensitivity matrix as 9 consider states (carried in P, never corrected by the forward "
                "filter; the smoother estimates them) with the scenario's σ (imu.spec gyro_g_sensitivity_deg_per_s_per_g; docs/error_state.md §5)");
  cmd->add_option("--scale-bias-compensation", mo->scale_bias_compensation,
                  "true/false: subtract the errors-in-variables bias of the scale-factor updates "
                  "(scale_factors.bias_compensation, default true; docs/consistency.md §3.6-3.7)");
  cmd->add_option("--smoother-eiv-regression", mo->smoother_eiv_regression,
                  "true/false: remove the errors-in-variables bias from the smoother's mean in every component by "
                  "regression on the scale states (default true, docs/consistency.md eq. E.7) or in the scale rows "
                  "only (false, eq. E.6)");
  cmd->add_flag("--step-velocity", mo->step_velocity, "Seed 000 step-averaged velocity aiding");
  cmd->add_option("--leg-length-m", mo->leg_length_m, "Inverted-pendulum length l of the step-length model [m]")
      ->check(CLI::Range(0.05, 3.0));
  auto shard = std::make_shared<std::string>();
  cmd->add_option("--shard", *shard,
                  "K/N: run only this share of the seeds (runs i with i mod N = K-1) into OUT/runs and OUT/shard.json, "
                  "for a cluster; combine the N folders with pednav montecarlo-merge (docs/scale.md)");
  cmd->callback([&action, mo, shard] {
    if (!shard->empty()) parse_shard(*shard, mo->shard_index, mo->shard_count);
    action = [mo] {
      if (auto ok = pipeline::run_montecarlo_command(*mo); !ok) {
        spdlog::error("{}", ok.error().message);
        return 1;
      }
      return 0;
    };
  });
}

}  // namespace pednav::apps

namespace pednav::apps {

void add_montecarlo_merge_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("montecarlo-merge",
                                 "Combine the shard folders of one pednav montecarlo --shard K/N study into runs.csv, "
                                 "nees.csv, summary.json and the figures, as one process writes them");
  auto out = std::make_shared<std::string>();
  auto dirs = std::make_shared<std::vector<std::string>>();
  auto plots = std::make_shared<bool>(true);
  cmd->add_option("OUT", *out, "Output folder")->required();
  cmd->add_option("SHARD_DIR", *dirs, "The shard output folders (each with shard.json and runs/)")->required();
  cmd->add_flag("!--no-plots", *plots, "No SVG figures");
  cmd->callback([&action, out, dirs, plots] {
    action = [out, dirs, plots] {
      if (auto ok = pipeline::run_montecarlo_merge(*out, *dirs, *plots); !ok) {
        spdlog::error("{}", ok.error().message);
        return 1;
      }
      return 0;
    };
  });
}

}  // namespace pednav::apps
