// SPDX-License-Identifier: BSD-2-Clause
// `pednav compare SOLUTION REFERENCE -o OUT`.
#include <spdlog/spdlog.h>

#include <sstream>

#include "apps/commands.hpp"
#include "pipeline/compare_command.hpp"

namespace pednav::apps {

void add_compare_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("compare", "Errors of a solution against a reference trajectory");
  auto args = std::make_shared<pipeline::CompareArgs>();
  auto sol_format = std::make_shared<std::string>("auto");
  auto ref_format = std::make_shared<std::string>("auto");
  auto align = std::make_shared<std::string>("none");
  auto qualities = std::make_shared<std::vector<int>>();
  cmd->add_option("SOLUTION", args->solution, "Solution: pednav CSV (solution/gnss/smoothed/truth), RTKLIB .pos")
      ->required();
  cmd->add_option("REFERENCE", args->reference, "Reference: NMEA GGA, RTKLIB .pos or CSV (see docs/cli.md)")
      ->required();
  cmd->add_option("-o,--out", args->out_dir, "Output folder")->required();
  cmd->add_option("--solution-format", *sol_format, "auto|csv|pos|nmea")->check(CLI::IsMember({"auto", "csv", "pos", "nmea"}));
  cmd->add_option("--reference-format", *ref_format, "auto|csv|pos|nmea")->check(CLI::IsMember({"auto", "csv", "pos", "nmea"}));
  cmd->add_option("--nmea-quality", *qualities, "GGA fix qualities to keep, e.g. 4 (RTK fixed); default all valid");
  cmd->add_option("--nmea-date", args->reference_read.nmea_date, "UTC date YYYY-MM-DD if the NMEA has no RMC");
  cmd->add_option("--align", *align,
                  "none|start|start-pyshoe|best-fit-2d|best-fit-3d (start: direction to the first reference point 1 m "
                  "out; start-pyshoe: PyShoe's align_plots, the first solution epoch 0.8 m out)")
      ->check(CLI::IsMember({"none", "start", "start-pyshoe", "best-fit-2d", "best-fit-3d"}));
  cmd->add_option("--tolerance", args->compare.time_tolerance_s, "Time matching tolerance [s] (default 0.05)");
  cmd->add_flag("--loop", args->compare.loop, "The path is a closed loop: report closure and % of distance");
  cmd->add_option("--segment", args->segment_s, "Per-segment statistics: segment length [s] (default 120)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("!--no-plot", args->plots, "Do not write the SVG plots");
  cmd->callback([&action, args, sol_format, ref_format, align, qualities] {
    action = [args, sol_format, ref_format, align, qualities] {
      args->solution_read.format = *io::parse_trajectory_format(*sol_format);
      args->reference_read.format = *io::parse_trajectory_format(*ref_format);
      args->reference_read.nmea_qualities = std::set<int>(qualities->begin(), qualities->end());
      args->compare.align = *align == "start"          ? eval::Align::kStart
                            : *align == "start-pyshoe" ? eval::Align::kStartPyshoe
                            : *align == "best-fit-2d" ? eval::Align::kBestFit2d
                            : *align == "best-fit-3d" ? eval::Align::kBestFit3d
                                                      : eval::Align::kNone;
      auto ev = pipeline::run_compare(*args);
      if (!ev) {
        spdlog::error("{}", ev.error().message);
        return 1;
      }
      spdlog::info("compared {} epochs ({:.1f} % available): horizontal RMS {:.3f} m, p95 {:.3f} m, max {:.3f} m",
                   ev->epochs_compared, ev->availability_pct, ev->horizontal_rms_m, ev->horizontal_p95_m,
                   ev->horizontal_max_m);
      return 0;
    };
  });
}

}  // namespace pednav::apps
