// SPDX-License-Identifier: BSD-2-Clause
// `pednav run CONFIG.yaml -o OUT`.
#include <spdlog/spdlog.h>

#include "apps/commands.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"

namespace pednav::apps {

void add_run_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand(
      "run", "Tightly coupled foot-IMU + GNSS filter (mode tc; also for a mode gnss file) or INS/ZUPT (mode ins)");
  auto config = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto mode = std::make_shared<std::string>();
  cmd->add_option("CONFIG", *config, "Run configuration (YAML)")->required();
  cmd->add_option("-o,--out", *out, "Output folder")->required();
  cmd->add_option("--mode", *mode, "Override the config's mode (tc|ins)")->check(CLI::IsMember({"tc", "ins"}));
  cmd->callback([&action, config, out, mode] {
    action = [config, out, mode] {
      auto cfg = io::load_run_config(*config);
      if (!cfg) {
        spdlog::error("{}", cfg.error().message);
        return 1;
      }
      if (!mode->empty()) cfg->mode = *mode;
      auto sum = pipeline::run_run_command(*cfg, *out);
      if (!sum) {
        spdlog::error("{}", sum.error().message);
        return 1;
      }
      return 0;
    };
  });
}

}  // namespace pednav::apps
