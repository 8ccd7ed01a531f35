// SPDX-License-Identifier: BSD-2-Clause
// `pednav zupt` (pipeline::run_zupt_command): zupt.csv / summary.json, and the agreement of a detector with the stance
// labels of the log (imu.format stance.column) — PyShoe's stored labels, or any reference the user has.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>

#include "io/config.hpp"
#include "pipeline/zupt_command.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::pipeline {
namespace {

using namespace pednav::io;

using ::testing::HasSubstr;

constexpr double kRateHz = 200.0;
constexpr double kPi = 3.14159265358979323846;

// 1 s still, 1 s rotating and shaking, 1 s still at 200 Hz: "t,gx,gy,gz,ax,ay,az,label"; the label column marks the
// still seconds as stance (or the moving one, `inverted`).
std::filesystem::path write_log(const std::filesystem::path& dir, bool inverted) {
  const auto path = dir / (inverted ? "inverted.csv" : "labelled.csv");
  std::ofstream os(path);
  os << std::setprecision(10) << "t,gx,gy,gz,ax,ay,az,label\n";
  for (int k = 0; k < 600; ++k) {
    const double t = k / kRateHz;
    const bool moving = k >= 200 && k < 400;
    double g[3] = {0, 0, 0}, a[3] = {0, 0, -9.80665};
    if (moving) {
      g[0] = 0.5, g[1] = 2.5 + std::sin(2 * kPi * 2 * t), g[2] = 0.2;
      a[0] += 4.0 * std::sin(2 * kPi * 3 * t), a[2] += 6.0 * std::cos(2 * kPi * 2 * t);
    }
    os << t << ',' << g[0] << ',' << g[1] << ',' << g[2] << ',' << a[0] << ',' << a[1] << ',' << a[2] << ','
       << ((moving != inverted) ? 0 : 1) << '\n';
  }
  return path;
}

Expected<ZuptCommandSummary> run(const std::filesystem::path& dir, const std::filesystem::path& log,
                                 const std::string& detector, bool label_column) {
  std::string yaml = "mode: ins\nimu:\n  file: " + log.string() +
                     "\n  format:\n    gyro: {columns: [1, 2, 3]}\n    accel: {columns: [4, 5, 6]}\n";
  if (label_column) yaml += "    stance: {column: 7}\n";
  yaml += "zupt:\n  detector: " + detector + "\n";
  auto c = parse_run_config(yaml, (dir / "zupt.yaml").string(), dir.string());
  if (!c) return c.error();
  return run_zupt_command(*c, (dir / ("out_" + detector)).string());
}

TEST(ZuptCommand, DetectorScoredAgainstTheLogsStanceLabels) {
  const auto dir = test::temp_dir_path("zupt_command");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto labelled = write_log(dir, false), inverted = write_log(dir, true);

  auto shoe = run(dir, labelled, "shoe", true);
  ASSERT_TRUE(shoe) << shoe.error().message;
  EXPECT_EQ(shoe->label_stance_samples, 400);
  // Measured 2026-12-05: precision 1.0000, recall 0.9850 (the window edges of each stance). Bounds: the recall's
  // miss rate × 2; the precision keeps 0.97 (an edge sample at the threshold may flip on another compiler).
  EXPECT_GT(shoe->label_precision, 0.97);  // window edges may flag a few moving samples
  EXPECT_GT(shoe->label_recall, 0.97);
  std::ifstream js(dir / "out_shoe" / "summary.json");
  std::stringstream ss;
  ss << js.rdbuf();
  EXPECT_THAT(ss.str(), HasSubstr("\"log_labels\""));
  EXPECT_THAT(ss.str(), HasSubstr("\"precision\""));
  EXPECT_TRUE(std::filesystem::exists(dir / "out_shoe" / "zupt.csv"));

  // Labels that call the moving second stance: the same detector now disagrees almost everywhere.
  auto wrong = run(dir, inverted, "shoe", true);
  ASSERT_TRUE(wrong) << wrong.error().message;
  EXPECT_EQ(wrong->label_stance_samples, 200);
  EXPECT_LT(wrong->label_precision, 0.01);  // measured 2026-12-05: 0 and 0
  EXPECT_LT(wrong->label_recall, 0.01);

  // Detector `labels` agrees with itself; without a label column no score, and `labels` is refused.
  auto self = run(dir, labelled, "labels", true);
  ASSERT_TRUE(self) << self.error().message;
  EXPECT_DOUBLE_EQ(self->label_precision, 1.0);
  EXPECT_DOUBLE_EQ(self->label_recall, 1.0);
  auto unlabelled = run(dir, labelled, "shoe", false);
  ASSERT_TRUE(unlabelled) << unlabelled.error().message;
  EXPECT_EQ(unlabelled->label_stance_samples, -1);
  auto refused = run(dir, labelled, "labels", false);
  ASSERT_FALSE(refused);
  EXPECT_THAT(refused.error().message, HasSubstr("zupt.detector labels: the IMU log has no stance labels"));
}

}  // namespace
}  // namespace pednav::pipeline
