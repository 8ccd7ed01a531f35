// SPDX-License-Identifier: BSD-2-Clause
// `pednav compare` with a pednav solution CSV that carries its own σ: evaluation.json "consistency" (share of epochs
// inside 3σ, normalized squared error), and no such block after an alignment that rotates the axes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/geodesy.hpp"
#include "pipeline/compare_command.hpp"

namespace pednav::pipeline {
namespace {

using namespace pednav::io;

const Eigen::Vector3d kOrigin_e = ecef_from_geodetic({51.08 * kDegToRad, -114.13 * kDegToRad, 1050.0});

std::string temp_dir(const std::string& name) {
  const auto d = std::filesystem::path(::testing::TempDir()) / ("pednav_compare_" + name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d.string();
}

// Reference: 20 epochs walking east at 1 m/s. Solution: east error 0.1 m (epochs 0-9) or 0.5 m (10-19) with
// σ_E = 0.1 m, north error 0.2 m with σ_N = 1 m, up error 0 with σ_U 0.3 m: 50 % inside 3σ, mean (q_E² + q_N²) =
// (10 · (1 + 0.04) + 10 · (25 + 0.04)) / 20 = 13.04, max |q| = 5.
void write_files(const std::string& dir) {
  std::ofstream ref(dir + "/ref.csv"), sol(dir + "/solution.csv");
  ref << "gps_week,gps_tow_s,x_m,y_m,z_m\n";
  sol << "gps_week,gps_tow_s,x_m,y_m,z_m,sd_n_m,sd_e_m,sd_d_m\n";
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d r = ecef_from_ned(Eigen::Vector3d(0.0, 1.0 * i, 0.0), kOrigin_e);
    const Eigen::Vector3d s = ecef_from_ned(Eigen::Vector3d(0.2, 1.0 * i + (i < 10 ? 0.1 : 0.5), 0.0), kOrigin_e);
    ref << fmt::format("2300,{:.1f},{:.4f},{:.4f},{:.4f}\n", 300000.0 + i, r.x(), r.y(), r.z());
    sol << fmt::format("2300,{:.1f},{:.4f},{:.4f},{:.4f},1.0,0.1,0.3\n", 300000.0 + i, s.x(), s.y(), s.z());
  }
}

// The comparison of the two files in `dir` into dir/out, without plots.
CompareArgs compare_args(const std::string& dir) {
  CompareArgs a;
  a.solution = dir + "/solution.csv";
  a.reference = dir + "/ref.csv";
  a.out_dir = dir + "/out";
  a.plots = false;
  return a;
}

TEST(CompareConsistency, SolutionSigmaIsScored) {
  const std::string dir = temp_dir("consistency");
  write_files(dir);
  auto ev = run_compare(compare_args(dir));
  ASSERT_TRUE(ev) << ev.error().message;
  std::ifstream in(dir + "/out/evaluation.json");
  const auto j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.contains("consistency")) << j.dump(2);
  const auto& c = j["consistency"];
  EXPECT_EQ(c["epochs_with_sigma"].get<int>(), 20);
  EXPECT_NEAR(c["inside_3sigma_pct"].get<double>(), 50.0, 1e-9);
  EXPECT_NEAR(c["inside_3sigma_vertical_pct"].get<double>(), 100.0, 1e-9);
  EXPECT_NEAR(c["mean_normalized_sq_horizontal"].get<double>(), 13.04, 1e-2);  // coordinates written to 0.1 mm
  EXPECT_NEAR(c["max_normalized_horizontal"].get<double>(), 5.0, 1e-2);
}

TEST(CompareConsistency, NoConsistencyBlockAfterARotatingAlignment) {
  const std::string dir = temp_dir("consistency_aligned");
  write_files(dir);
  CompareArgs a = compare_args(dir);
  a.compare.align = eval::Align::kStart;
  ASSERT_TRUE(run_compare(a));
  std::ifstream in(dir + "/out/evaluation.json");
  EXPECT_FALSE(nlohmann::json::parse(in).contains("consistency"));
}

}  // namespace
}  // namespace pednav::pipeline
