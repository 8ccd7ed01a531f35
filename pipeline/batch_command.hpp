// SPDX-License-Identifier: BSD-2-Clause
// `pednav batch MANIFEST -o OUT [--shard K/N]` (docs/scale.md): many configurations of a field campaign, each run by
// its command (run, gnss, outage) into OUT/<name>/; an index of successes and failures with the error line; resumable
// (an item whose OUT/<name>/batch_status.json says ok is not redone); one summary table (accuracy per log when the
// configuration has a reference).
#pragma once

#include <string>
#include <vector>

#include "core/expected.hpp"

namespace pednav::pipeline {

/// One manifest entry.
struct BatchItem {
  std::string name;     ///< output folder name (unique; letters, digits, '-', '_', '.')
  std::string command;  ///< run | gnss | outage
  std::string config;   ///< configuration file (relative paths: to the manifest's folder)
  std::string mode;     ///< run: override the configuration's mode (tc | ins), empty = as configured
  int keep_sats = 0;    ///< outage: satellites kept in the windows (0 = full outage)
};

/// Reads a manifest: YAML (`items:` a list of {name, command, config[, mode][, keep_sats]}) or CSV (header row with
/// name,command,config[,mode][,keep_sats]); every problem at once, naming the file, line or item.
Expected<std::vector<BatchItem>> read_batch_manifest(const std::string& path);

struct BatchResult {
  int items = 0, ok = 0, failed = 0, skipped_done = 0;
  std::string table;  ///< the summary table (also OUT/summary.csv), for the log
};

/// Runs the manifest's items (all, or with shard_count > 1 those with index mod N = K − 1) into out_dir, then writes
/// out_dir/index.csv and out_dir/summary.csv over the items of this invocation's share (done now or before).
Expected<BatchResult> run_batch_command(const std::string& manifest, const std::string& out_dir, int shard_index = 1,
                                        int shard_count = 1);

}  // namespace pednav::pipeline
