// SPDX-License-Identifier: BSD-2-Clause
// `pednav calibrate CONFIG.yaml -o OUT`: the work is pipeline::run_calibrate_command.
#include <spdlog/spdlog.h>

#include "apps/commands.hpp"
#include "io/config.hpp"
#include "pipeline/calibrate_command.hpp"

namespace pednav::apps {

void add_calibrate_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand(
      "calibrate",
      "Calibrate an IMU log from itself: still periods, gyro bias, noise densities, gravity axis, rate, saturation, "
      "gait -> calibration.yaml (imu.spec + SHOE threshold) and calibration.json");
  auto config = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  cmd->add_option("CONFIG", *config, "A configuration with imu.file and imu.format (YAML)")->required();
  cmd->add_option("-o,--out", *out, "Output folder")->required();
  cmd->callback([&action, config, out] {
    action = [config, out] {
      auto cfg = io::load_run_config(*config);
      if (!cfg) {
        spdlog::error("{}", cfg.error().message);
        return 1;
      }
      auto r = pipeline::run_calibrate_command(*cfg, *out);
      if (!r) {
        spdlog::error("{}", r.error().message);
        return 1;
      }
      for (const auto& w : r->self.calibration.warnings) spdlog::warn("calibration: {}", w);
      spdlog::info("{} -> {}", r->summary, *out);
      return 0;
    };
  });
}

}  // namespace pednav::apps
