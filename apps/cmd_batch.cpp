// SPDX-License-Identifier: BSD-2-Clause
// `pednav batch MANIFEST -o OUT [--shard K/N]`: the work is pipeline::run_batch_command.
#include <spdlog/spdlog.h>

#include <sstream>

#include "apps/commands.hpp"
#include "pipeline/batch_command.hpp"

namespace pednav::apps {

void add_batch_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("batch",
                                 "Run the configurations of a manifest (run, gnss, outage) into OUT/<name>/: index.csv of "
                                 "successes and failures, summary.csv of accuracy; resumable");
  auto manifest = std::make_shared<std::string>();
  auto out = std::make_shared<std::string>();
  auto shard = std::make_shared<std::string>();
  cmd->add_option("MANIFEST", *manifest, "YAML (items: [{name, command, config, mode, keep_sats}]) or CSV")->required();
  cmd->add_option("-o,--out", *out, "Output folder")->required();
  cmd->add_option("--shard", *shard, "K/N: only the items with index mod N = K-1 (docs/scale.md)");
  cmd->callback([&action, manifest, out, shard] {
    int k = 1, n = 1;
    if (!shard->empty()) parse_shard(*shard, k, n);
    action = [manifest, out, k, n] {
      auto r = pipeline::run_batch_command(*manifest, *out, k, n);
      if (!r) {
        spdlog::error("{}", r.error().message);
        return 1;
      }
      spdlog::info("batch: {} items, {} ok ({} done before), {} failed -> {}/index.csv, summary.csv\n{}", r->items, r->ok,
                   r->skipped_done, r->failed, *out, r->table);
      return r->failed > 0 ? 1 : 0;
    };
  });
}

}  // namespace pednav::apps
