// SPDX-License-Identifier: BSD-2-Clause
// `pednav report OUTDIR`: one self-contained report.html of a run folder (io/report.hpp).
#include <spdlog/spdlog.h>

#include "apps/commands.hpp"
#include "io/report.hpp"

namespace pednav::apps {

void add_report_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("report", "One self-contained HTML page (tables + plots) of a run folder");
  auto dir = std::make_shared<std::string>();
  cmd->add_option("OUTDIR", *dir, "Run folder (output of pednav run / gnss / outage)")->required();
  cmd->callback([&action, dir] {
    action = [dir] {
      auto r = io::run_report_command(*dir);
      if (!r) {
        spdlog::error("{}", r.error().message);
        return 1;
      }
      for (const auto& w : r->warnings) spdlog::warn("report: {}", w);
      spdlog::info("report with {} plots: {}", r->plots, r->path);
      return 0;
    };
  });
}

}  // namespace pednav::apps
