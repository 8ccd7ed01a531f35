// SPDX-License-Identifier: BSD-2-Clause
// libFuzzer target: run configuration and scenario YAML (io/yaml_schema, io/config, io/scenario_config).
// Input: byte 0 selects run config (even) or scenario (odd), the rest is the YAML text. Any input must give a
// configuration or an error, never a crash or a hang; an accepted run configuration must round-trip through
// to_yaml and turn into engine options without crashing.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "io/config.hpp"
#include "pipeline/run_command.hpp"
#include "io/scenario_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  if (data[0] % 2 == 0) {
    auto cfg = pednav::io::parse_run_config(text, "fuzz.yaml", "/nonexistent");
    if (!cfg) {
      if (cfg.error().message.empty()) std::abort();  // an error always says something
      return 0;
    }
    const std::string again = pednav::io::to_yaml(*cfg);
    (void)pednav::io::parse_run_config(again, "resolved.yaml", "/nonexistent");
    (void)pednav::pipeline::engine_options(*cfg).problems();
  } else {
    // Along-a-track scenarios name a track file: relative paths resolve under a folder that does not exist.
    auto sc = pednav::io::parse_scenario(text, "fuzz_scenario.yaml", "/nonexistent");
    if (!sc && sc.error().message.empty()) std::abort();
  }
  return 0;
}
