// SPDX-License-Identifier: BSD-2-Clause
// `pednav simulate SCENARIO.yaml -o OUT`: thin registration; the work is pipeline::run_simulate_command.
#include <spdlog/spdlog.h>

#include "apps/commands.hpp"
#include "io/scenario_config.hpp"
#include "pipeline/simulate_command.hpp"

namespace pednav::apps {

void add_simulate_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("simulate", "Synthetic walk: truth, foot IMU, rover + base RINEX, nav RINEX, config");
  auto path = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  cmd->add_option("SCENARIO", *path, "Scenario file (YAML, see datasets/README.md)")->required();
  cmd->add_option("-o,--output", *out,
                  "Output folder (truth.csv, imu.csv, rover.obs, base.obs, nav.rnx, blunders.csv, config.yaml)")
      ->required();
  cmd->callback([&action, path, out] {
    action = [path, out] {
      auto sc = io::load_scenario(*path);
      if (!sc) {
        spdlog::error("{}", sc.error().message);
        return 1;
      }
      auto sum = pipeline::run_simulate_command(*sc, *out);
      if (!sum) {
        spdlog::error("{}", sum.error().message);
        return 1;
      }
      spdlog::info("simulate: {:.1f} s, {:.1f} m, {} strides, {} IMU samples, {} rover / {} base epochs, {} blunders, "
                   "{} saturated IMU samples, peak rate {:.2f} rad/s, in {:.2f} s -> {}",
                   sum->duration_s, sum->distance_m, sum->strides, sum->imu_samples, sum->rover_epochs,
                   sum->base_epochs, sum->blunder_events, sum->saturated_samples, sum->max_gyro_radps, sum->wall_s, *out);
      if (sum->carrier_phase)
        spdlog::info("simulate: L1 carrier phase, {} losses of lock, slips and half-cycle events -> slips.csv",
                     sum->carrier_events);
      return 0;
    };
  });
}

}  // namespace pednav::apps
