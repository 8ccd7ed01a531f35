// SPDX-License-Identifier: BSD-2-Clause
// `pednav config-check` and `pednav rinex-info`: inspect inputs before a run.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <map>

#include "apps/commands.hpp"
#include "io/config.hpp"
#include "io/rinex_summary.hpp"
#include "pipeline/run_command.hpp"

namespace pednav::apps {

void add_config_check_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("config-check", "Validate a run configuration and print it resolved");
  auto path = std::make_shared<std::string>();
  cmd->add_option("CONFIG", *path, "Run configuration (YAML)")->required();
  cmd->callback([&action, path] {
    action = [path] {
      auto cfg = io::load_run_config(*path);
      if (!cfg) {
        spdlog::error("{}", cfg.error().message);
        return 1;
      }
      // What `pednav run` would reject before reading data, then the files it would not find: all at once.
      auto problems = pipeline::run_config_problems(*cfg);
      for (const auto& m : io::missing_input_files(*cfg)) problems.push_back(m);
      if (!problems.empty()) {
        for (const auto& m : problems) spdlog::error("{}: {}", *path, m);
        return 1;
      }
      std::fputs(io::to_yaml(*cfg).c_str(), stdout);
      return 0;
    };
  });
}

void add_rinex_info_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("rinex-info", "Summarize a RINEX observation file (epochs, satellites, signals)");
  auto path = std::make_shared<std::string>();
  auto systems = std::make_shared<std::string>("GREJC");
  cmd->add_option("OBS", *path, "RINEX observation file")->required();
  cmd->add_option("--systems", *systems, "Constellations to read, e.g. GR (default GREJC)");
  cmd->callback([&action, path, systems] {
    action = [path, systems] {
      auto text = io::summarize_rinex_obs(*path, *systems);
      if (!text) {
        spdlog::error("{}", text.error().message);
        return 1;
      }
      std::fputs(text->c_str(), stdout);
      return 0;
    };
  });
}

}  // namespace pednav::apps
