// SPDX-License-Identifier: BSD-2-Clause
// `pednav compare SOLUTION REFERENCE -o OUT`: errors of a solution against a reference trajectory.
#pragma once

#include <string>

#include "core/expected.hpp"
#include "eval/trajectory.hpp"
#include "io/trajectory_io.hpp"

namespace pednav::pipeline {

struct CompareArgs {
  std::string solution;
  std::string reference;
  std::string out_dir;
  io::TrajectoryReadOptions solution_read;
  io::TrajectoryReadOptions reference_read;
  eval::CompareOptions compare;
  double segment_s = 120.0;  ///< per-segment statistics: segment length [s]
  bool plots = true;         ///< write trajectory_en.svg, error_vs_time.svg, error_cdf.svg (gnuplot)
};

/// evaluation.json content (keys of DESIGN.md plus context).
std::string evaluation_json(const eval::Evaluation& ev, const CompareArgs& args, const io::TrajectoryFile& sol,
                            const io::TrajectoryFile& ref);
/// evaluation.md: the same figures as a table, including the seed 004 bin table.
std::string evaluation_markdown(const eval::Evaluation& ev, const CompareArgs& args);
/// Read, compare, write OUT/evaluation.json, OUT/evaluation.md, OUT/errors.csv, OUT/error_cdf.csv and the plots
/// (atomically; a missing gnuplot only warns).
Expected<eval::Evaluation> run_compare(const CompareArgs& args);

}  // namespace pednav::pipeline
