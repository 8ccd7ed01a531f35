// SPDX-License-Identifier: BSD-2-Clause
// Each subcommand registers itself on the CLI11 app; its work is done by a function in pipeline/ (testable).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <sstream>
#include <string>

namespace pednav::apps {

/// Callback run after parsing if its subcommand was chosen; returns the process exit code.
using Action = std::function<int()>;

void add_config_check_command(CLI::App& app, Action& action);
void add_rinex_info_command(CLI::App& app, Action& action);
void add_compare_command(CLI::App& app, Action& action);
void add_gnss_command(CLI::App& app, Action& action);
void add_simulate_command(CLI::App& app, Action& action);
void add_run_command(CLI::App& app, Action& action);
void add_calibrate_command(CLI::App& app, Action& action);
void add_montecarlo_command(CLI::App& app, Action& action);
void add_montecarlo_merge_command(CLI::App& app, Action& action);
void add_batch_command(CLI::App& app, Action& action);
void add_outage_command(CLI::App& app, Action& action);
void add_report_command(CLI::App& app, Action& action);
void add_zupt_command(CLI::App& app, Action& action);
void add_hmm_train_command(CLI::App& app, Action& action);

/// `--shard K/N` (montecarlo, batch): K and N, 1 <= K <= N; a CLI11 validation error naming the option otherwise.
inline void parse_shard(const std::string& text, int& k, int& n) {
  char slash = 0;
  std::istringstream in(text);
  if (!(in >> k >> slash >> n) || slash != '/' || !in.eof() || n < 1 || k < 1 || k > n)
    throw CLI::ValidationError("--shard", "expected K/N with 1 <= K <= N, got '" + text + "'");
}

}  // namespace pednav::apps
