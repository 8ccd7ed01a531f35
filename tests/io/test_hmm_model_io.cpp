// SPDX-License-Identifier: BSD-2-Clause
// Tests of io/hmm_model_io.*: hmm.yaml round trip, bad model files, zupt.hmm_* config keys.
#include "io/hmm_model_io.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/atomic_file.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::io {
namespace {

using ::testing::HasSubstr;

std::string temp_path(const std::string& name) {
  const auto dir = test::temp_dir_path("hmm_model_io");
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

TEST(HmmModelIo, RoundTrip) {
  HmmModelFile f;
  f.model = ins::seed002_initial_model();
  f.extraction = {"-y", 0.05, 1.0};
  f.training.logs = {"a.csv", "b.csv"};
  f.training.observations = 241;
  f.training.iterations = 33;
  f.training.converged = true;
  f.training.log_likelihood_initial = -399.18;
  f.training.log_likelihood_final = -270.70;
  const std::string path = temp_path("hmm.yaml");
  ASSERT_TRUE(write_file_atomic(path, hmm_model_yaml(f)));
  auto g = read_hmm_model(path);
  ASSERT_TRUE(g) << g.error().message;
  constexpr double kTolWritten = 1e-6;  // 6 significant digits in the file
  EXPECT_LT((g->model.A - f.model.A).cwiseAbs().maxCoeff(), kTolWritten);
  EXPECT_LT((g->model.B - f.model.B).cwiseAbs().maxCoeff(), kTolWritten);
  EXPECT_EQ(g->extraction.gyro_axis, "-y");
  EXPECT_NEAR(g->extraction.grade_width_radps, 1.0, kTolWritten);
  EXPECT_EQ(g->training.iterations, 33);
  EXPECT_EQ(g->training.logs.size(), 2u);
}

TEST(HmmModelIo, BadFilesNameTheProblem) {
  const std::string path = temp_path("bad.yaml");
  {
    std::ofstream os(path);
    os << "A: [[1, 0], [0, 1]]\nB: [[1]]\npi: [1, 0, 0, 0]\nextraction: {gyro_axis: w, smooth_window_s: 0.05, "
          "grade_width_deg_per_s: 60}\nbogus: 1\n";
  }
  auto g = read_hmm_model(path);
  ASSERT_FALSE(g);
  EXPECT_THAT(g.error().message, HasSubstr("A: expected 4 lists of 4 numbers"));
  EXPECT_THAT(g.error().message, HasSubstr("B: expected 4 lists of 15 numbers"));
  EXPECT_THAT(g.error().message, HasSubstr("gyro_axis: expected x, y, z, -x, -y or -z"));
  EXPECT_THAT(g.error().message, HasSubstr("bogus"));
  auto missing = read_hmm_model(temp_path("does_not_exist.yaml"));
  ASSERT_FALSE(missing);
  EXPECT_THAT(missing.error().message, HasSubstr("cannot open HMM model file"));
}

TEST(HmmModelIo, ConfigKeysAndModelConsistency) {
  HmmModelFile f;
  f.model = ins::seed002_initial_model();
  f.extraction = {"y", 0.05, 60.0 * 3.14159265358979323846 / 180.0};
  const std::string model = temp_path("model.yaml");
  ASSERT_TRUE(write_file_atomic(model, hmm_model_yaml(f)));
  const std::string base = "mode: ins\nimu: {file: x.csv}\nzupt:\n  detector: hmm\n";
  auto ok = parse_run_config(base + "  hmm_model: " + model + "\n  hmm_gyro_axis: y\n", "c.yaml", ".");
  ASSERT_TRUE(ok) << ok.error().message;
  ASSERT_TRUE(ok->zupt.hmm_model.has_value());
  const ins::ZuptDetectorOptions o = zupt_detector_options(ok->zupt);
  EXPECT_EQ(o.detector, "hmm");
  EXPECT_EQ(o.hmm_observations.axis, 1);
  EXPECT_EQ(o.hmm_observations.sign, 1.0);
  auto mismatch = parse_run_config(base + "  hmm_model: " + model + "\n  hmm_gyro_axis: -z\n", "c.yaml", ".");
  ASSERT_FALSE(mismatch);
  EXPECT_THAT(mismatch.error().message, HasSubstr("trained with gyro_axis y"));
  auto bad = parse_run_config(base + "  hmm_gyro_axis: q\n  hmm_decoder: beam\n", "c.yaml", ".");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("zupt.hmm_gyro_axis: expected x, y, z, -x, -y or -z"));
  EXPECT_THAT(bad.error().message, HasSubstr("zupt.hmm_decoder"));
  int axis = 0;
  double sign = 0;
  EXPECT_TRUE(parse_gyro_axis("-x", axis, sign));
  EXPECT_EQ(axis, 0);
  EXPECT_EQ(sign, -1.0);
  EXPECT_FALSE(parse_gyro_axis("yy", axis, sign));
}

}  // namespace
}  // namespace pednav::io
