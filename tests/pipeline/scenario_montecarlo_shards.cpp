// SPDX-License-Identifier: BSD-2-Clause
// `pednav montecarlo --shard K/N` + `pednav montecarlo-merge` (docs/scale.md): 40 runs as one process and as 4 shards
// merged give byte-identical runs.csv (without its wall_s column), nees.csv and summary.json (without its wall-clock
// and thread-count keys); a missing, duplicated or foreign shard is a clear error naming it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pipeline/montecarlo_command.hpp"
#include "tests/sim/fixtures.hpp"
#include "tests/support/data.hpp"

namespace pednav::pipeline {
namespace {

using ::testing::HasSubstr;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// runs.csv without column 4 (wall_s).
std::string runs_without_wall(const std::string& path) {
  std::istringstream in(slurp(path));
  std::string out, line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    for (size_t i = 0; i < cells.size(); ++i) {
      if (i != 3) out += cells[i] + (i + 1 < cells.size() ? "," : "");
    }
    out += "\n";
  }
  return out;
}

std::string summary_without_wall(const std::string& path) {
  auto j = nlohmann::json::parse(slurp(path));
  for (const char* k : {"wall_s", "run_wall_s_sum", "jobs", "runs_done_now"}) j.erase(k);
  return j.dump();
}

MontecarloArgs study(const std::string& out) {
  MontecarloArgs a;
  a.scenario_path = test::source_path("datasets/indoor_loops.yaml");
  a.out_dir = out;
  a.runs = 40;
  a.jobs = 2;
  a.plots = false;
  return a;
}

TEST(MontecarloShards, FourShardsMergedEqualOneProcess) {
  const std::string dir = test::temp_dir("mc_shards");
  ASSERT_TRUE(run_montecarlo_command(study(dir + "/one")).has_value());
  std::vector<std::string> shards;
  for (int k = 1; k <= 4; ++k) {
    MontecarloArgs a = study(dir + "/shard_" + std::to_string(k));
    a.shard_index = k;
    a.shard_count = 4;
    ASSERT_TRUE(run_montecarlo_command(a).has_value()) << k;
    shards.push_back(a.out_dir);
    EXPECT_FALSE(std::filesystem::exists(a.out_dir + "/summary.json"));  // a shard has no statistics of its own
    EXPECT_TRUE(std::filesystem::exists(a.out_dir + "/shard.json"));
  }
  ASSERT_TRUE(run_montecarlo_merge(dir + "/merged", shards, false).has_value());
  EXPECT_EQ(slurp(dir + "/one/nees.csv"), slurp(dir + "/merged/nees.csv"));
  EXPECT_EQ(runs_without_wall(dir + "/one/runs.csv"), runs_without_wall(dir + "/merged/runs.csv"));
  EXPECT_EQ(summary_without_wall(dir + "/one/summary.json"), summary_without_wall(dir + "/merged/summary.json"));
  for (int i = 0; i < 40; ++i) {  // every run file, copied from its shard
    char name[32];
    std::snprintf(name, sizeof name, "/runs/run_%04d.csv", i);
    // Same seed, same run; only the wall time in the '#' header line differs.
    const std::string a = slurp(dir + "/one" + name), b = slurp(dir + "/merged" + name);
    ASSERT_FALSE(b.empty()) << name;
    EXPECT_EQ(a.substr(a.find('\n')), b.substr(b.find('\n'))) << name;
  }

  // Missing, duplicated and foreign shards.
  auto missing = run_montecarlo_merge(dir + "/m1", {shards[0], shards[1], shards[3]}, false);
  ASSERT_FALSE(missing);
  EXPECT_THAT(missing.error().message, HasSubstr("missing shards 3 of 4"));
  auto twice = run_montecarlo_merge(dir + "/m2", {shards[0], shards[1], shards[1], shards[2], shards[3]}, false);
  ASSERT_FALSE(twice);
  EXPECT_THAT(twice.error().message, HasSubstr("shard 2/4 given twice"));
  MontecarloArgs other = study(dir + "/other_3");
  other.shard_index = 3;
  other.shard_count = 4;
  other.seed_offset = 1000;
  ASSERT_TRUE(run_montecarlo_command(other).has_value());
  auto foreign = run_montecarlo_merge(dir + "/m3", {shards[0], shards[1], other.out_dir, shards[3]}, false);
  ASSERT_FALSE(foreign);
  EXPECT_THAT(foreign.error().message, HasSubstr("shard of a different study"));
  auto none = run_montecarlo_merge(dir + "/m4", {dir + "/one"}, false);
  ASSERT_FALSE(none);
  EXPECT_THAT(none.error().message, HasSubstr("shard.json: cannot read"));
}

}  // namespace
}  // namespace pednav::pipeline
