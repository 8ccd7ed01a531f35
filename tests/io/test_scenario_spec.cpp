// SPDX-License-Identifier: BSD-2-Clause
// Scenario imu.spec: a preset name, or a map overriding the preset's values (simulation only: the written run
// configuration names the preset, so a map makes a filter/simulator model-mismatch study).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/geodesy.hpp"
#include "ins/imu_spec.hpp"
#include "io/scenario_config.hpp"

namespace pednav::io {
namespace {

using ::testing::HasSubstr;

std::string forest_walk_with_spec(const std::string& spec_line) {
  std::ifstream in(std::string(PEDNAV_SOURCE_DIR) + "/datasets/forest_walk.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::string key = "  spec: crista";
  const size_t at = text.find(key);
  EXPECT_NE(at, std::string::npos);
  text.replace(at, key.size(), spec_line);
  return text;
}

TEST(ScenarioSpec, AMapOverridesThePresetValues) {
  const auto sc = parse_scenario(forest_walk_with_spec("  spec: {preset: crista, gyro_range_deg_per_s: 2000, "
                                                       "accel_scale_ppm: 0}"),
                                 "scenario.yaml", std::string(PEDNAV_SOURCE_DIR) + "/datasets");
  ASSERT_TRUE(sc) << sc.error().message;
  const ins::ImuSpec crista = *ins::imu_spec_preset("crista");
  const ins::ImuSpec& s = sc->scenario.imu.spec;
  EXPECT_NEAR(s.gyro_range, 2000.0 * kDegToRad, 1e-12);
  EXPECT_EQ(s.accel_scale_sigma, 0.0);
  EXPECT_DOUBLE_EQ(s.gyro_arw, crista.gyro_arw);  // not overridden: the preset's
  EXPECT_DOUBLE_EQ(s.accel_bias_initial, crista.accel_bias_initial);
  EXPECT_EQ(sc->imu_spec_preset, "crista");
}

TEST(ScenarioSpec, UnknownKeyOrPresetInTheMapIsAnError) {
  const std::string dir = std::string(PEDNAV_SOURCE_DIR) + "/datasets";
  const auto bad_key = parse_scenario(forest_walk_with_spec("  spec: {preset: crista, gyro_rang_deg_per_s: 2000}"),
                                      "scenario.yaml", dir);
  ASSERT_FALSE(bad_key);
  EXPECT_THAT(bad_key.error().message, HasSubstr("gyro_rang_deg_per_s"));
  EXPECT_THAT(bad_key.error().message, HasSubstr("scenario.yaml"));
  const auto bad_preset =
      parse_scenario(forest_walk_with_spec("  spec: {preset: cristal}"), "scenario.yaml", dir);
  ASSERT_FALSE(bad_preset);
  EXPECT_THAT(bad_preset.error().message, HasSubstr("cristal"));
}

// imu.carry (docs/sim.md §9): foot (default) or hand; anything else names the file, line and key.
TEST(ScenarioSpec, CarryIsFootOrHand) {
  const std::string dir = std::string(PEDNAV_SOURCE_DIR) + "/datasets";
  const auto foot = parse_scenario(forest_walk_with_spec("  spec: crista"), "scenario.yaml", dir);
  ASSERT_TRUE(foot) << foot.error().message;
  EXPECT_EQ(foot->scenario.imu.carry, "foot");
  const auto hand = parse_scenario(forest_walk_with_spec("  spec: crista\n  carry: hand"), "scenario.yaml", dir);
  ASSERT_TRUE(hand) << hand.error().message;
  EXPECT_EQ(hand->scenario.imu.carry, "hand");
  const auto pocket = parse_scenario(forest_walk_with_spec("  spec: crista\n  carry: pocket"), "scenario.yaml", dir);
  ASSERT_FALSE(pocket);
  EXPECT_THAT(pocket.error().message, HasSubstr("scenario.yaml:"));
  EXPECT_THAT(pocket.error().message, HasSubstr("imu.carry: expected one of {foot, hand}, got 'pocket'"));
}

}  // namespace
}  // namespace pednav::io
