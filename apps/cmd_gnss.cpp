// SPDX-License-Identifier: BSD-2-Clause
// `pednav gnss CONFIG.yaml -o OUT`: thin registration; the work is pipeline::run_gnss_command.
#include <spdlog/spdlog.h>

#include "apps/commands.hpp"
#include "io/config.hpp"
#include "pipeline/gnss_command.hpp"

namespace pednav::apps {

void add_gnss_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("gnss", "GNSS-only epoch-by-epoch least squares (SD with a base, else undifferenced)");
  auto path = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  cmd->add_option("CONFIG", *path, "Run configuration (YAML)")->required();
  cmd->add_option("-o,--output", *out, "Output folder (gnss.csv, gnss.pos, summary.json)")->required();
  cmd->callback([&action, path, out] {
    action = [path, out] {
      auto cfg = io::load_run_config(*path);
      if (!cfg) {
        spdlog::error("{}", cfg.error().message);
        return 1;
      }
      auto sum = pipeline::run_gnss_command(*cfg, *out);
      if (!sum) {
        spdlog::error("{}", sum.error().message);
        return 1;
      }
      spdlog::info("gnss: {} of {} epochs solved ({} with velocity) in {:.2f} s -> {}", sum->epochs_solved,
                   sum->epochs_read, sum->epochs_with_velocity, sum->wall_s, *out);
      return 0;
    };
  });
}

}  // namespace pednav::apps
