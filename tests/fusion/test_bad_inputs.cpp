// SPDX-License-Identifier: BSD-2-Clause
// Bad input to the forward engine and to `pednav run` (issue 5 "Bad input"): clear errors, messages asserted.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "core/geodesy.hpp"
#include "fusion/engine.hpp"
#include "io/config.hpp"
#include "io/hmm_model_io.hpp"
#include "pipeline/run_command.hpp"

namespace pednav {
namespace {

using ::testing::HasSubstr;

constexpr double kRateHz = 100.0;
constexpr double kGravityMps2 = 9.81;

// A foot IMU at rest (level, gravity on -z... i.e. specific force +z up in a z-up body) for `duration_s`,
// optionally spinning about the vertical at `spin_radps` (then the ZUPT detector never fires).
std::vector<ins::ImuSample> imu_log(GpsTime t0, double duration_s, double spin_radps) {
  std::vector<ins::ImuSample> v;
  const int n = static_cast<int>(duration_s * kRateHz);
  for (int i = 0; i < n; ++i) {
    ins::ImuSample s;
    s.t = t0.plus_ns(static_cast<int64_t>(i) * 10'000'000);
    s.omega_ib_b = Eigen::Vector3d(0.0, 0.0, spin_radps);
    s.f_ib_b = Eigen::Vector3d(0.0, 0.0, -kGravityMps2);  // body z down (FRD): specific force points up = -z
    v.push_back(s);
  }
  return v;
}

const GpsTime kT0 = GpsTime::from_week_tow(2300, 100000.0);
const Eigen::Vector3d kPosition = ecef_from_geodetic(Geodetic{51.08 * kDegToRad, -114.13 * kDegToRad, 1050.0});

// mode ins with the initial position and heading given: what is left to fail is the input under test.
fusion::EngineOptions ins_options() {
  fusion::EngineOptions o;
  o.mode = fusion::Mode::kInsOnly;
  o.initial_position_e = kPosition;
  o.initial_yaw_rad = 0.0;
  return o;
}

TEST(EngineBadInput, GnssAndImuSpansThatDoNotOverlap) {
  const auto imu = imu_log(kT0, 60.0, 0.0);
  std::vector<gnss::ObsEpoch> rover(3);
  for (int i = 0; i < 3; ++i) rover[i].time = kT0.plus_s(3600.0 + i);  // an hour after the IMU log
  gnss::NavData nav;
  fusion::EngineInputs in;
  in.imu = &imu;
  in.rover = &rover;
  in.nav = &nav;
  fusion::EngineOptions o;
  auto r = fusion::run_forward(in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("time spans do not overlap"));
  EXPECT_THAT(r.error().message, HasSubstr("GNSS ("));
  EXPECT_THAT(r.error().message, HasSubstr("IMU ("));
}

TEST(EngineBadInput, ImuWithoutAStillPeriod) {
  const auto imu = imu_log(kT0, 30.0, 3.0);  // spinning at 3 rad/s the whole time
  fusion::EngineInputs in;
  in.imu = &imu;
  fusion::EngineOptions o = ins_options();
  auto r = fusion::run_forward(in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("no still period found"));
}

TEST(EngineBadInput, TightlyCoupledWithBaseObservationsButNoBasePosition) {
  const auto imu = imu_log(kT0, 60.0, 0.0);
  std::vector<gnss::ObsEpoch> rover(3), base(3);
  for (int i = 0; i < 3; ++i) rover[i].time = base[i].time = kT0.plus_s(10.0 + i);
  gnss::NavData nav;
  fusion::EngineInputs in;
  in.imu = &imu;
  in.rover = &rover;
  in.base = &base;
  in.nav = &nav;
  fusion::EngineOptions o;  // tc, base_position_e unset
  auto r = fusion::run_forward(in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("base observations given without a base position"));
}

TEST(EngineBadInput, InsModeWithoutInitialPositionOrHeading) {
  const auto imu = imu_log(kT0, 10.0, 0.0);
  fusion::EngineInputs in;
  in.imu = &imu;
  fusion::EngineOptions o;
  o.mode = fusion::Mode::kInsOnly;
  auto r = fusion::run_forward(in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("mode ins needs an initial position"));
  o.initial_position_e = kPosition;
  r = fusion::run_forward(in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("mode ins needs an initial heading (initial.yaw_deg)"));
}

TEST(EngineBadInput, TooFewImuSamplesAndBadOptions) {
  const auto imu = imu_log(kT0, 0.05, 0.0);
  fusion::EngineInputs in;
  in.imu = &imu;
  fusion::EngineOptions o;
  o.mode = fusion::Mode::kInsOnly;
  auto r = fusion::run_forward(in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("IMU: fewer than 10 samples"));
  o.fault_probability = 1.5;
  o.zupt_sigma_mps = 0.0;
  r = fusion::run_forward(in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("fault_rejection.probability must be in (0.5, 1)"));
  EXPECT_THAT(r.error().message, HasSubstr("zupt.sigma_mps must be > 0"));
}

// zupt.detector labels needs one 0/1 label per IMU sample (io: imu.format stance.column).
TEST(EngineBadInput, LabelsDetectorWithoutLabelsOrWithTheWrongCount) {
  const auto imu = imu_log(kT0, 10.0, 0.0);
  fusion::EngineInputs in;
  in.imu = &imu;
  fusion::EngineOptions o = ins_options();
  o.zupt.detector = "labels";
  auto r = fusion::run_forward(in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("zupt.detector labels: the IMU log has no stance labels"));
  const std::vector<uint8_t> labels(imu.size() - 3, 1);
  in.stance_labels = &labels;
  r = fusion::run_forward(in, o);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("997 stance labels for 1000 IMU samples"));
}

TEST(RunConfigBadInput, ZuptFormEIsAConfigError) {
  auto c = io::parse_run_config(
      "mode: tc\nrover_obs: r.obs\nbase_obs: b.obs\nnav: n.rnx\nimu:\n  file: imu.csv\n  format: pyshoe\n"
      "zupt:\n  form: E\n",
      "run.yaml", "/data");
  ASSERT_FALSE(c);
  EXPECT_THAT(c.error().message, HasSubstr("run.yaml:9: zupt.form: expected one of {D, F}, got 'E'"));
}

TEST(RunConfigBadInput, ZaruGateProbabilityOutsideItsRange) {
  auto c = io::parse_run_config(
      "mode: ins\nimu:\n  file: imu.csv\n  format: pyshoe\nzupt:\n  zaru_gate_probability: 0.3\n", "run.yaml", "/data");
  ASSERT_FALSE(c);
  EXPECT_THAT(c.error().message, HasSubstr("zupt.zaru_gate_probability: must be 0 (no gate) or in (0.5, 1)"));
  fusion::EngineOptions o;
  o.zaru_gate_probability = 1.0;
  ASSERT_FALSE(o.problems().empty());
  EXPECT_THAT(o.problems().back(), HasSubstr("zupt.zaru_gate_probability must be 0 (no gate) or in (0.5, 1)"));
}

TEST(RunConfigBadInput, FaultWindowIsAWholeNumberOfEpochsWithinItsRange) {
  const std::string head = "mode: ins\nimu:\n  file: imu.csv\n  format: pyshoe\nfault_rejection:\n";
  auto ok = io::parse_run_config(head + "  window_epochs: 4\n", "run.yaml", "/data");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->fault_rejection_window_epochs, 4);
  for (const char* bad : {"17", "-1", "2.5"}) {
    auto c = io::parse_run_config(head + "  window_epochs: " + bad + "\n", "run.yaml", "/data");
    ASSERT_FALSE(c) << bad;
    EXPECT_THAT(c.error().message, HasSubstr("fault_rejection.window_epochs")) << bad;
  }
  fusion::EngineOptions o;
  o.fault_window_epochs = fusion::kMaxFaultWindowEpochs + 1;
  ASSERT_FALSE(o.problems().empty());
  EXPECT_THAT(o.problems().back(), HasSubstr("fault_rejection.window_epochs must be in [0, 16]"));
}

TEST(RunConfigBadInput, ShoeAdaptivePeakRateIsDegreesPerSecondAndNotNegative) {
  const std::string head = "mode: ins\nimu:\n  file: imu.csv\n  format: pyshoe\nzupt:\n";
  auto ok = io::parse_run_config(head + "  shoe_adaptive_min_peak_rate_deg_per_s: 180\n", "run.yaml", "/data");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_NEAR(io::zupt_detector_options(ok->zupt).shoe_adaptive_min_peak_radps, 3.14159265358979, 1e-12);
  auto bad = io::parse_run_config(head + "  shoe_adaptive_min_peak_rate_deg_per_s: -5\n", "run.yaml", "/data");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message,
              HasSubstr("run.yaml:6: zupt.shoe_adaptive_min_peak_rate_deg_per_s: value -5 is out of range"));
}

TEST(RunCommandBadInput, ImuLogWithoutAStillPeriodNamesTheConfig) {
  const auto dir = std::filesystem::temp_directory_path() / ("pednav_test_fusion_bad_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir / "imu.csv");
    f.precision(12);
    f << "i,t_s,gx,gy,gz,ax,ay,az\n";  // columns are 0-based: time 1, gyro 2-4, accel 5-7
    int i = 0;
    for (const auto& s : imu_log(kT0, 20.0, 3.0)) {
      f << i++ << "," << s.t.tow_s() << ",0,0,3,0,0,-9.81\n";
    }
  }
  const Geodetic g = geodetic_from_ecef(kPosition);
  const std::string yaml =
      "mode: ins\nimu:\n  file: imu.csv\n  spec: crista\n  format:\n    delimiter: \",\"\n    header_lines: 1\n"
      "    time: {base: gps_sow, column: 1, unit: s, gps_week: 2300}\n"
      "    gyro: {columns: [2, 3, 4], unit: rad_per_s}\n    accel: {columns: [5, 6, 7], unit: mps2}\n"
      "initial: {lat_deg: " + std::to_string(g.lat * kRadToDeg) + ", lon_deg: " + std::to_string(g.lon * kRadToDeg) +
      ", h_m: 1050, yaw_deg: 0}\n";
  auto c = io::parse_run_config(yaml, (dir / "run.yaml").string(), dir.string());
  ASSERT_TRUE(c) << c.error().message;
  auto r = pipeline::run_run_command(*c, (dir / "out").string());
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("run.yaml: IMU: no still period found"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out" / "solution.csv"));
  std::filesystem::remove_all(dir);
}

// A mode gnss file without an IMU log: run names what it lacks and where the GNSS-only solution is (issue 49 item 8:
// with the IMU log it runs as tc, tests/apps/scenario_obvious_next_command.cpp).
TEST(RunCommandBadInput, ModeGnssWithoutImuSaysWhatIsMissing) {
  auto c = io::parse_run_config("mode: gnss\nrover_obs: r.obs\nnav: n.rnx\n", "run.yaml", "/data");
  ASSERT_TRUE(c) << c.error().message;
  auto r = pipeline::run_run_command(*c, "/nonexistent/out");
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message,
              HasSubstr("run.yaml: mode gnss: pednav run runs the tightly coupled filter, which needs imu.file "
                        "(missing here); `pednav gnss` gives the GNSS-only solution"));
}

}  // namespace
}  // namespace pednav
