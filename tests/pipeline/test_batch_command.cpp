// SPDX-License-Identifier: BSD-2-Clause
// The batch manifest reader (pipeline/batch_command.hpp): keep_sats and the item keys are checked, not converted
// blindly (a YAML `keep_sats: 1e71` threw out of main, a CSV cell beyond int went through std::atoi).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "pipeline/batch_command.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav::pipeline {
namespace {

using ::testing::HasSubstr;

class BatchManifest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir("batch_manifest");
    std::ofstream(dir_ + "/run.yaml") << "mode: ins\n";
  }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ + "/" + name) << text;
    return dir_ + "/" + name;
  }
  std::string dir_;
};

TEST_F(BatchManifest, KeepSatsIsAnIntegerAtLeastZero) {
  auto ok =
      read_batch_manifest(write("ok.yaml", "items:\n  - {name: a, command: outage, config: run.yaml, keep_sats: 4}\n"));
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->front().keep_sats, 4);
  auto yaml = read_batch_manifest(write("bad.yaml",
                                        "items:\n  - {name: a, command: outage, config: run.yaml, keep_sats: 1e71}\n"
                                        "  - {name: b, command: outage, config: run.yaml, keep_sats: -2}\n"
                                        "  - {name: c, command: outage, config: run.yaml, keep_sats: [3]}\n"
                                        "  - {name: {x: 1}, command: run, config: run.yaml}\n"));
  ASSERT_FALSE(yaml);
  const std::string& m = yaml.error().message;
  EXPECT_THAT(m, HasSubstr("items[1]: keep_sats: expected an integer >= 0, got '1e71'"));
  EXPECT_THAT(m, HasSubstr("items[2]: keep_sats: expected an integer >= 0, got '-2'"));
  EXPECT_THAT(m, HasSubstr("items[3]: keep_sats: expected a number"));
  EXPECT_THAT(m, HasSubstr("items[4]: name: expected a string"));
  auto csv = read_batch_manifest(write("bad.csv",
                                       "name,command,config,keep_sats\na,outage,run.yaml,99999999999\n"
                                       "b,outage,run.yaml, 3\n"));
  ASSERT_FALSE(csv);
  EXPECT_THAT(csv.error().message, HasSubstr("bad.csv:2: keep_sats: expected an integer >= 0, got '99999999999'"));
  EXPECT_THAT(csv.error().message, ::testing::Not(HasSubstr("bad.csv:3")));
}

}  // namespace
}  // namespace pednav::pipeline
