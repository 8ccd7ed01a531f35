// SPDX-License-Identifier: BSD-2-Clause
// The run files of `pednav montecarlo` (pipeline/montecarlo_command.hpp): OUT/runs/run_NNNN.csv, one per seed, written
// atomically and read back to resume a study or merge its shards (lossless: 17 digits).
#pragma once

#include <cstdint>
#include <string>

#include "core/expected.hpp"
#include "eval/montecarlo.hpp"

namespace pednav::pipeline {

/// One finished run (what runs.csv shows), with its per-epoch errors and (carrier studies) its carrier figures.
struct RunRecord {
  int index = 0;
  uint64_t seed = 0;
  bool ok = false;
  std::string message;
  double wall_s = 0.0;
  double distance_m = 0.0;
  eval::McRun run;
};

/// OUT/runs/run_NNNN.csv of run i.
std::string run_file(const std::string& out, int i);

/// Writes one run's file: a '#' line with the run facts (index, seed, ok, wall_s, distance_m, the carrier figures when
/// scored, message last), the column header, one row per epoch and solution.
Expected<void> write_run(const std::string& path, const RunRecord& r);

/// Reads a file write_run wrote; errors name the file and line.
Expected<RunRecord> read_run(const std::string& path);

}  // namespace pednav::pipeline
