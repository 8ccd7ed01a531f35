// SPDX-License-Identifier: BSD-2-Clause
// pednav command-line front end: parses arguments, sets up logging, dispatches to one subcommand.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>

#include "apps/commands.hpp"
#include "io/log.hpp"

int main(int argc, char** argv) {
  CLI::App app{"pednav: foot-mounted IMU + high-sensitivity GNSS positioning (post-processing)"};
  app.set_version_flag("--version", std::string("pednav ") + PEDNAV_VERSION);
  bool verbose = false, quiet = false;
  std::string log_file;
  app.add_flag("-v,--verbose", verbose, "More log output (debug level)");
  app.add_flag("-q,--quiet", quiet, "Only errors; no progress display");
  app.add_option("--log-file", log_file, "Also write the full log to this file");
  app.require_subcommand(1);

  pednav::apps::Action action;
  pednav::apps::add_config_check_command(app, action);
  pednav::apps::add_rinex_info_command(app, action);
  pednav::apps::add_compare_command(app, action);
  pednav::apps::add_gnss_command(app, action);
  pednav::apps::add_simulate_command(app, action);
  pednav::apps::add_run_command(app, action);
  pednav::apps::add_calibrate_command(app, action);
  pednav::apps::add_montecarlo_command(app, action);
  pednav::apps::add_montecarlo_merge_command(app, action);
  pednav::apps::add_batch_command(app, action);
  pednav::apps::add_outage_command(app, action);
  pednav::apps::add_report_command(app, action);
  pednav::apps::add_zupt_command(app, action);
  pednav::apps::add_hmm_train_command(app, action);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  const auto verbosity = quiet ? pednav::io::Verbosity::kQuiet
                         : verbose ? pednav::io::Verbosity::kVerbose
                                   : pednav::io::Verbosity::kNormal;
  if (auto ok = pednav::io::setup_logging(verbosity, log_file); !ok) {
    std::fprintf(stderr, "error: %s\n", ok.error().message.c_str());
    return 2;
  }
  if (!action) {
    std::fprintf(stderr, "error: no subcommand given (see --help)\n");
    return 2;
  }
  return action();
}
