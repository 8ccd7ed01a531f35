// SPDX-License-Identifier: BSD-2-Clause
// `pednav outage CONFIG.yaml -o OUT`: GNSS outage study (pipeline/outage_command.hpp).
#include <spdlog/spdlog.h>

#include "apps/commands.hpp"
#include "io/config.hpp"
#include "pipeline/outage_command.hpp"

namespace pednav::apps {

void add_outage_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand(
      "outage", "GNSS outage study: K windows of D s, full or partial (keep N satellites), forward and smoothed");
  auto config = std::make_shared<std::string>();
  auto args = std::make_shared<pipeline::OutageArgs>();
  auto full = std::make_shared<bool>(false);
  auto keep = std::make_shared<int>(-1);
  auto keep_by = std::make_shared<std::string>("elevation");
  cmd->add_option("CONFIG", *config,
                  "Run configuration (YAML; any mode with the IMU log and GNSS files: the study runs tc)")
      ->required();
  cmd->add_option("-o,--out", args->out_dir, "Output folder")->required();
  cmd->add_option("--windows", args->windows,
                  "Number of windows after convergence, one per K-th of the span, where the reference covers it "
                  "(default 5)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--duration", args->duration_s, "Window length [s] (default 100)")->check(CLI::PositiveNumber);
  cmd->add_option("--starts", args->start_tow_s, "Explicit window starts, GPS seconds of week (instead of --windows)");
  auto* f = cmd->add_flag("--full", *full, "Full outages: no GNSS at all inside the windows");
  auto* k = cmd->add_option("--keep-sats", *keep,
                            "Partial outages: drop the lowest-elevation satellite while more than N remain")
                ->check(CLI::Range(1, 64));
  f->excludes(k);
  cmd->add_option("--keep-by", *keep_by, "elevation (seed 004) | cn0: which satellites the partial outage keeps")
      ->check(CLI::IsMember({"elevation", "cn0"}));
  cmd->add_option("--against", args->against,
                  "auto|reference|run: error against the configured reference (auto if set) or the run without outage")
      ->check(CLI::IsMember({"auto", "reference", "run"}));
  cmd->add_option("--converged-sigma-m", args->converged_sigma_horizontal_m,
                  "Convergence: horizontal 1-sigma of the run without outage [m] (default 1)");
  cmd->add_option("--converged-yaw-deg", args->converged_sigma_yaw_deg, "Convergence: yaw 1-sigma [deg] (default 2)");
  cmd->add_option("--settle", args->settle_s, "First window no earlier than this after convergence [s] (default 30)");
  cmd->add_option("--jobs", args->jobs, "Windows run in parallel (default 1)")->check(CLI::Range(1, 64));
  cmd->add_flag("!--no-plot", args->plot, "Do not write outage_rms.svg");
  cmd->add_flag("--write-runs", args->write_runs, "Also write window_<k>/solution.csv (+ smoothed.csv) of each run");
  auto mode = std::make_shared<std::string>();
  cmd->add_option("--mode", *mode, "Accepted for older scripts: the study always runs the tightly coupled filter")
      ->check(CLI::IsMember({"tc"}));
  cmd->callback([&action, config, args, full, keep, keep_by, mode] {
    action = [config, args, full, keep, keep_by, mode] {
      if (!*full && *keep < 0) {
        spdlog::error("outage: choose --full or --keep-sats N");
        return 1;
      }
      args->keep_sats = *full ? 0 : *keep;
      args->keep_by = *keep_by == "cn0" ? eval::KeepBy::kCn0 : eval::KeepBy::kElevation;
      auto cfg = io::load_run_config(*config);
      if (!cfg) {
        spdlog::error("{}", cfg.error().message);
        return 1;
      }
      if (!mode->empty()) cfg->mode = *mode;
      auto r = pipeline::run_outage_command(*cfg, *args);
      if (!r) {
        spdlog::error("{}", r.error().message);
        return 1;
      }
      spdlog::info("{} windows, error vs {}: forward max {:.2f} m, RMS at end {:.2f} m{}", r->windows.size(),
                   r->against, r->forward.max_error_m, r->forward.rms_at_end_m,
                   r->has_smoothed ? fmt::format("; smoothed max {:.2f} m, RMS at end {:.2f} m",
                                                 r->smoothed.max_error_m, r->smoothed.rms_at_end_m)
                                   : std::string());
      return 0;
    };
  });
}

}  // namespace pednav::apps
