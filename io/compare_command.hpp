// `pednav compare SOLUTION REFERENCE -o OUT`: errors of a solution against a reference trajectory.
#pragma once

#include <string>

#include "core/expected.hpp"
#include "eval/trajectory.hpp"
#include "io/trajectory_io.hpp"

namespace pednav::io {

struct CompareArgs {
  std::string solution;
  std::string reference;
  std::string out_dir;
  TrajectoryReadOptions solution_read;
  TrajectoryReadOptions reference_read;
  eval::CompareOptions compare;
};

/// evaluation.json content (keys of DESIGN.md plus context).
std::string evaluation_json(const eval::Evaluation& ev, const CompareArgs& args, const TrajectoryFile& sol,
                            const TrajectoryFile& ref);
/// evaluation.md: the same figures as a table, including the seed 004 bin table.
std::string evaluation_markdown(const eval::Evaluation& ev, const CompareArgs& args);
/// Read, compare, write OUT/evaluation.json, OUT/evaluation.md and OUT/errors.csv (atomically).
Expected<eval::Evaluation> run_compare(const CompareArgs& args);

}  // namespace pednav::io
