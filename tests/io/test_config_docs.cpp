// SPDX-License-Identifier: BSD-2-Clause
// docs/configuration.md cannot drift from the configuration readers (issue 49 item 7): every key that the run
// configuration reader (io::run_config_keys) and the scenario reader (io::scenario_config_keys) accept is in the first
// column of a table of its part of the page, and every key in such a first column is one that reader accepts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <set>
#include <string>
#include <vector>

#include "io/config.hpp"
#include "io/scenario_config.hpp"
#include "tests/support/data.hpp"
#include "tests/support/doc_tables.hpp"

namespace pednav {
namespace {

struct DocumentedKeys {
  std::set<std::string> run, scenario;
  std::vector<std::string> problems;  ///< a dotted continuation without a key before it
};

// First-column keys, with the page's notation expanded: `.name` continues the previous key's path (its last
// component replaced), `[]` marks a list's items. Tables after the "Scenario files" heading are the scenario's.
// A key as the page writes it: an optional leading '.', then dot-separated names [a-z_][a-z0-9_]*, each
// optionally followed by "[]". (Hand-written: GCC 12's std::regex trips -Wmaybe-uninitialized under ASan -O2.)
bool is_key_notation(const std::string& code) {
  size_t i = (!code.empty() && code[0] == '.') ? 1 : 0;
  for (;;) {
    if (i >= code.size() || !(std::islower(static_cast<unsigned char>(code[i])) || code[i] == '_')) return false;
    while (i < code.size() && (std::islower(static_cast<unsigned char>(code[i])) ||
                               std::isdigit(static_cast<unsigned char>(code[i])) || code[i] == '_')) {
      ++i;
    }
    if (code.compare(i, 2, "[]") == 0) i += 2;
    if (i == code.size()) return true;
    if (code[i] != '.') return false;
    ++i;
  }
}

DocumentedKeys documented_keys(const std::string& markdown) {
  DocumentedKeys d;
  for (const auto& row : test::doc_table_rows(markdown)) {
    const bool scenario = row.section.rfind("Scenario files", 0) == 0;
    std::string previous;
    for (const std::string& code : row.codes) {
      if (!is_key_notation(code)) continue;
      std::string full = code;
      if (code[0] == '.') {
        const size_t dot = previous.rfind('.');
        if (dot == std::string::npos) {
          d.problems.push_back("docs/configuration.md:" + std::to_string(row.line) + ": `" + code +
                               "` continues no dotted key");
          continue;
        }
        full = previous.substr(0, dot) + code;
      }
      previous = full;
      (scenario ? d.scenario : d.run).insert(full);
    }
  }
  return d;
}

// A key the reader accepts is documented when the page names it or a key below it (a section such as `gnss` or
// `route.waypoints` is documented by its keys).
bool documented(const std::string& k, const std::set<std::string>& docs) {
  if (docs.count(k)) return true;
  const auto it = docs.lower_bound(k);
  for (auto i = it; i != docs.end() && i->rfind(k, 0) == 0; ++i) {
    const char next = (*i)[k.size()];
    if (next == '.' || next == '[') return true;
  }
  return false;
}

void expect_same(const std::vector<std::string>& accepted, const std::set<std::string>& docs, const std::string& what) {
  ASSERT_GT(accepted.size(), 50u) << what << ": the reader's key list looks incomplete";
  const std::set<std::string> acc(accepted.begin(), accepted.end());
  for (const auto& k : accepted) {
    EXPECT_TRUE(documented(k, docs)) << what << " key `" << k << "` is accepted but not in docs/configuration.md";
  }
  for (const auto& k : docs) {
    EXPECT_TRUE(acc.count(k)) << "docs/configuration.md documents " << what << " key `" << k
                              << "`, which the reader does not accept";
  }
}

TEST(ConfigDocs, EveryRunConfigurationKeyIsDocumentedAndEveryDocumentedKeyIsAccepted) {
  const DocumentedKeys d = documented_keys(test::doc_text(test::source_path("docs/configuration.md")));
  for (const auto& p : d.problems) ADD_FAILURE() << p;
  expect_same(io::run_config_keys(), d.run, "run configuration");
}

TEST(ConfigDocs, EveryScenarioKeyIsDocumentedAndEveryDocumentedKeyIsAccepted) {
  const DocumentedKeys d = documented_keys(test::doc_text(test::source_path("docs/configuration.md")));
  expect_same(io::scenario_config_keys(), d.scenario, "scenario");
}

// The key lists are what the readers mark as known: a key from the list is never "unknown", one outside it is.
TEST(ConfigDocs, KeyListsAreWhatTheReadersAccept) {
  const std::vector<std::string> keys = io::run_config_keys();
  for (const char* k : {"mode", "gnss.ambiguity.ratio_threshold", "imu.format.time.base", "imu.spec.gyro_scale_ppm",
                        "imu.format.mag.columns", "initial.lat_deg", "zupt.shoe_threshold"}) {
    EXPECT_NE(std::find(keys.begin(), keys.end(), k), keys.end()) << k;
  }
  EXPECT_EQ(std::find(keys.begin(), keys.end(), "gnss.no_such_key"), keys.end());
  auto bad = io::parse_run_config("mode: tc\ngnss: {no_such_key: 1}\n", "x.yaml", ".");
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message.find("gnss.no_such_key: unknown key"), std::string::npos) << bad.error().message;
  const std::vector<std::string> sk = io::scenario_config_keys();
  for (const char* k : {"seed", "route.waypoints[].e_m", "route.shape.laps", "track.gnss.rover_obs",
                        "gnss.attenuation[].tau_s", "imu.spec.preset", "gnss.rover_clock.bias_ms"}) {
    EXPECT_NE(std::find(sk.begin(), sk.end(), k), sk.end()) << k;
  }
}

}  // namespace
}  // namespace pednav
