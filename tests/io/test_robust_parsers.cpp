// SPDX-License-Identifier: BSD-2-Clause
// Robustness of the readers (issue 11, docs/robustness.md): fault injection into IMU logs (truncation at every
// offset, NaN/inf fields, saturation, gaps, backwards time, duplicate bursts, unit mistakes) and the inputs the
// fuzz targets of fuzz/ found. Every input gives data or an error naming the file and line, never a crash or NaN.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <string>

#include "core/geodesy.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "io/scenario_config.hpp"
#include "io/trajectory_io.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::io {
namespace {

using ::testing::HasSubstr;

constexpr double kG_mps2 = 9.80665;
constexpr int kRows = 300;                 // 3 s at 100 Hz
constexpr double kSaturation_radps = 300.0 * kDegToRad;

// A walking-like log at 100 Hz: 1 s still, then a sinusoidal pitch rate (below full scale).
std::string walk_csv(int rows = kRows) {
  std::ostringstream os;
  os << std::setprecision(10) << "t,gx,gy,gz,ax,ay,az\n";
  for (int i = 0; i < rows; ++i) {
    const double t = i * 0.01;
    const double wy = t < 1.0 ? 0.0 : 3.0 * std::sin(2.0 * std::numbers::pi * t);
    os << t << ",0.001," << wy << ",-0.002,0.01,0.02," << -kG_mps2 + (t < 1.0 ? 0.0 : 2.0 * std::cos(2.0 * std::numbers::pi * t))
       << "\n";
  }
  return os.str();
}

ImuFormat basic() {
  ImuFormat f;
  f.name = "test";
  f.gyro_columns = {1, 2, 3};
  f.accel_columns = {4, 5, 6};
  f.gyro_full_scale = kSaturation_radps;
  return f;
}

Expected<ImuLog> parse(const std::string& text, const ImuFormat& f = basic()) {
  return parse_imu_csv(text.data(), text.size(), "imu.csv", f);
}

void expect_finite_and_increasing(const ImuLog& log) {
  for (size_t i = 0; i < log.samples.size(); ++i) {
    ASSERT_TRUE(log.samples[i].omega_ib_b.allFinite() && log.samples[i].f_ib_b.allFinite()) << "sample " << i;
    if (i > 0) {
      ASSERT_LT(log.samples[i - 1].t, log.samples[i].t) << "sample " << i;
    }
  }
}

// Truncation at every byte offset of the data (many of them mid-line): either an error naming the file, or a log
// whose rows are a prefix of the full log's, with the cut row reported and dropped.
TEST(RobustImuFault, TruncationAtEveryOffsetCompletesWithTruncationReportedOrFailsClearly) {
  const std::string full = walk_csv();
  auto whole = parse(full);
  ASSERT_TRUE(whole) << whole.error().message;
  ASSERT_EQ(whole->report.truncated_rows, 0);
  int ok = 0, failed = 0, reported = 0;
  for (size_t cut = 1; cut < full.size(); ++cut) {
    auto log = parse(full.substr(0, cut));
    if (!log) {
      ++failed;
      EXPECT_THAT(log.error().message, HasSubstr("imu.csv")) << "cut at " << cut;
      continue;
    }
    ++ok;
    expect_finite_and_increasing(*log);
    ASSERT_LE(log->samples.size(), whole->samples.size());
    for (size_t i = 0; i < log->samples.size(); ++i) {
      ASSERT_EQ(log->samples[i].t, whole->samples[i].t) << "cut at " << cut;
      ASSERT_EQ(log->samples[i].omega_ib_b, whole->samples[i].omega_ib_b) << "cut at " << cut << ": a cut number was kept";
      ASSERT_EQ(log->samples[i].f_ib_b, whole->samples[i].f_ib_b) << "cut at " << cut << ": a cut number was kept";
    }
    const bool mid_line = full[cut - 1] != '\n';
    EXPECT_EQ(log->report.truncated_rows, mid_line ? 1 : 0) << "cut at " << cut;
    if (mid_line) {
      ++reported;
      std::string all;
      for (const auto& w : log->report.warnings) all += w;
      EXPECT_THAT(all, HasSubstr("has no line end: the file was cut off")) << "cut at " << cut;
    }
  }
  EXPECT_GT(ok, 0);
  EXPECT_GT(failed, 0);  // cuts in the first rows leave too few samples
  EXPECT_GT(reported, 0);
}

TEST(RobustImuFault, NanAndInfFieldsAreDroppedAndCounted) {
  std::string text = walk_csv();
  for (const char* bad : {"nan", "inf", "-inf", "NaN", "1e999", ""}) {
    const std::string row = "\n1.5,";
    const auto at = text.find(row);
    ASSERT_NE(at, std::string::npos);
    text.replace(at + row.size(), text.find(',', at + row.size()) - at - row.size(), bad);
    auto log = parse(text);
    ASSERT_TRUE(log) << bad << ": " << log.error().message;
    expect_finite_and_increasing(*log);
    EXPECT_EQ(log->report.bad_rows, 1) << bad;
    EXPECT_EQ(log->samples.size(), static_cast<size_t>(kRows - 1)) << bad;
    std::string all;
    for (const auto& w : log->report.warnings) all += w;
    EXPECT_THAT(all, HasSubstr("rows with NaN/empty/unparsable fields dropped; first at imu.csv:152")) << bad;
    text = walk_csv();
  }
}

TEST(RobustImuFault, SaturatedSamplesAreCountedAndWarned) {
  std::string text = walk_csv();
  for (int k = 1; k <= 5; ++k) {  // 5 samples at the 300 deg/s full scale (clipped swing)
    const std::string row = "\n2.0" + std::to_string(k) + ",";
    const auto at = text.find(row);
    ASSERT_NE(at, std::string::npos) << row;
    const auto e = text.find('\n', at + 1);
    text.replace(at + 1, e - at - 1, "2.0" + std::to_string(k) + ",0.001,5.2359877,-0.002,0.01,0.02,-9.8");
  }
  auto log = parse(text);
  ASSERT_TRUE(log) << log.error().message;
  EXPECT_EQ(log->report.saturated_samples, 5);
  std::string all;
  for (const auto& w : log->report.warnings) all += w;
  EXPECT_THAT(all, HasSubstr("5 samples at >= 99.9 % of the configured full scale (saturated)"));
}

TEST(RobustImuFault, TwoSecondGapIsAnErrorNamingTheLine) {
  std::string text = walk_csv(600);
  const auto a = text.find("\n2,"), b = text.find("\n4,");
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  text.erase(a, b - a);  // rows 2.00 .. 3.99 s missing
  auto log = parse(text);
  ASSERT_FALSE(log);
  EXPECT_THAT(log.error().message, HasSubstr("imu.csv:202: gap of 2.0100 s exceeds the bridging limit max_gap_s = 0.1 s"));
}

TEST(RobustImuFault, BackwardsTimestampIsAnErrorNamingTheLine) {
  std::string text = walk_csv();
  text.insert(text.find("\n1.5,") + 1, "1.2,0,0,0,0,0,-9.8\n");
  auto log = parse(text);
  ASSERT_FALSE(log);
  EXPECT_THAT(log.error().message, HasSubstr("imu.csv:152: time 1.200000 s is not after the previous 1.490000 s"));
}

TEST(RobustImuFault, DuplicateBurstIsDroppedAndCounted) {
  std::string text = walk_csv();
  const auto at = text.find("\n1.5,") + 1;
  const std::string row = text.substr(at, text.find('\n', at) - at + 1);
  for (int k = 0; k < 10; ++k) text.insert(at, row);  // a burst of 10 repeated packets
  auto log = parse(text);
  ASSERT_TRUE(log) << log.error().message;
  expect_finite_and_increasing(*log);
  EXPECT_EQ(log->report.duplicates_dropped, 10);
  EXPECT_EQ(log->report.duplicates_differing, 0);
  EXPECT_EQ(log->samples.size(), static_cast<size_t>(kRows));
}

TEST(RobustImuFault, WrongUnitsInTheConfigAreNamed) {
  ImuFormat g = basic();
  g.accel_unit = "g";  // m/s^2 log declared as g
  auto a = parse(walk_csv(), g);
  ASSERT_FALSE(a);
  EXPECT_THAT(a.error().message, HasSubstr("accel.unit is probably mps2, not g"));
  ImuFormat rad = basic();
  rad.gyro_full_scale = 0.0;
  std::string text = walk_csv();
  text += "3,0.001,171.9,-0.002,0.01,0.02,-9.8\n";  // a deg/s log declared as rad/s: 172 "rad/s"
  auto w = parse(text, rad);
  ASSERT_FALSE(w);
  EXPECT_THAT(w.error().message, HasSubstr("gyro.unit is probably deg_per_s, not rad_per_s"));
  // Through the configuration: an unknown unit is a config error with its YAML path.
  auto cfg = parse_run_config("mode: ins\nimu: {file: imu.csv, spec: crista, format: {gyro: {unit: rpm}}}\n", "run.yaml", ".");
  ASSERT_FALSE(cfg);
  EXPECT_THAT(cfg.error().message, HasSubstr("imu.format.gyro.unit"));
}

TEST(RobustImuFuzzFinding, TimeStampBeyondTheGpsTimeRangeIsABadRowNotAnOverflow) {
  std::string text = walk_csv();
  text.insert(text.find("\n1.5,") + 1, "1e300,0,0,0,0,0,-9.8\n");
  auto log = parse(text);
  ASSERT_TRUE(log) << log.error().message;
  EXPECT_EQ(log->report.bad_rows, 1);
  std::string all;
  for (const auto& w : log->report.warnings) all += w;
  EXPECT_THAT(all, HasSubstr("first at imu.csv:152: time 1e+300 s is out of range"));
  ImuFormat sow = basic();
  sow.time_base = "gps_sow";
  sow.gps_week = 2000000000;  // week * ns per week overflows int64
  auto far = parse(walk_csv(), sow);
  ASSERT_FALSE(far);
  EXPECT_THAT(far.error().message, HasSubstr("0 usable IMU samples"));
  EXPECT_THAT(far.error().message, HasSubstr("is out of range"));
}

// Found by fuzz/fuzz_config (UBSan: float-cast-overflow in read_columns): a column index of 1e71 is a non-negative
// whole number, so it passed the old check and was cast to int; in the Release build config-check accepted it and
// `pednav run` then rejected the wrapped value. Every integer read from YAML is now range-checked before the cast.
// The input is fuzz/corpus/fuzz_config/run_columns_1e71.yaml (after its selector byte).
TEST(RobustConfigFuzzFinding, ColumnIndexBeyondIntIsAnErrorNamingTheKey) {
  auto cfg = parse_run_config(
      "mode: ins\nimu:\n  file: imu.csv\n  spec: crista\n  format:\n"
      "    accel: {columns: [1e71, 2, 3]}\n",
      "run.yaml", ".");
  ASSERT_FALSE(cfg);
  EXPECT_THAT(cfg.error().message,
              HasSubstr("run.yaml:6: imu.format.accel.columns: value 1e71 is out of range [0, 10000]"));
  EXPECT_EQ(cfg.error().message.find('\n'), std::string::npos) << "one line: " << cfg.error().message;
  for (const char* bad : {"-1", "1.5", "x", "4294967297"}) {
    auto c = parse_run_config(
        std::string("mode: ins\nimu: {file: imu.csv, spec: crista, format: {gyro: {columns: [0, ") + bad + ", 2]}}}\n",
        "run.yaml", ".");
    ASSERT_FALSE(c) << bad;
    EXPECT_THAT(c.error().message, HasSubstr("imu.format.gyro.columns: ")) << bad;
  }
  for (const char* key : {"header_lines: 1e71", "time: {column: -3e40}", "stance: {column: 1e10}"}) {
    auto c = parse_run_config(std::string("mode: ins\nimu: {file: imu.csv, spec: crista, format: {") + key + "}}\n",
                              "run.yaml", ".");
    ASSERT_FALSE(c) << key;
    EXPECT_THAT(c.error().message, HasSubstr("is out of range")) << key;
  }
}

// The same pattern read the GGA fix qualities of a run's reference and of a scenario's track.
TEST(RobustConfigFuzzFinding, NmeaQualitiesBeyondIntAreErrorsNamingTheKey) {
  auto cfg = parse_run_config(
      "mode: ins\nimu: {file: imu.csv, format: pyshoe, spec: crista}\n"
      "reference: {file: ref.nmea, format: nmea, nmea_qualities: [4, 1e71]}\n",
      "run.yaml", ".");
  ASSERT_FALSE(cfg);
  EXPECT_THAT(cfg.error().message,
              HasSubstr("run.yaml:3: reference.nmea_qualities: value 1e71 is out of range [1, 9]"));
  auto fraction = parse_run_config(
      "mode: ins\nimu: {file: imu.csv, format: pyshoe, spec: crista}\n"
      "reference: {file: ref.nmea, format: nmea, nmea_qualities: [4.5]}\n",
      "run.yaml", ".");
  ASSERT_FALSE(fraction);
  EXPECT_THAT(fraction.error().message, HasSubstr("reference.nmea_qualities: expected an integer, got '4.5'"));
  auto sc = parse_scenario(
      "name: t\nseed: 1\ntrack:\n  file: track.nmea\n  nmea_qualities: [1e71]\n"
      "  gnss: {rover_obs: r.obs, nav: n.nav}\n",
      "scenario.yaml", "/nonexistent");
  ASSERT_FALSE(sc);
  EXPECT_THAT(sc.error().message,
              HasSubstr("scenario.yaml:5: track.nmea_qualities: value 1e71 is out of range [1, 9]"));
}

// Inputs found by fuzz/fuzz_trajectory (UBSan: signed overflow in the nanosecond count of a far-future date).
// This process's temporary folder, made once.
const std::string& kTempDir() {
  static const std::string dir = test::temp_dir("robust_parsers");
  return dir;
}

class RobustTrajectoryFuzzFinding : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) {
    const std::string p = (std::filesystem::path(kTempDir()) / name).string();
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
};

TEST_F(RobustTrajectoryFuzzFinding, PosWithAFarFutureYearIsAnError) {
  const std::string p = write("year.pos", "% GPST latitude(deg) longitude(deg) height(m)\n"
                                          "2060000/03/05 12:00:00.000 53.28 -9.05 75.1 1 9\n");
  auto r = read_rtklib_pos(p);
  ASSERT_FALSE(r);
  EXPECT_THAT(r.error().message, HasSubstr("/year.pos:2: expected 'YYYY/MM/DD HH:MM:SS.SSS' time"));
}

TEST_F(RobustTrajectoryFuzzFinding, PosAndCsvWithAnAbsurdWeekAreErrors) {
  auto pos = read_rtklib_pos(write("week.pos", "% GPST x-ecef(m) y-ecef(m) z-ecef(m)\n99999999999 1 3822100 -609600 5083000 1 8\n"));
  ASSERT_FALSE(pos);
  EXPECT_THAT(pos.error().message, HasSubstr("/week.pos:2: expected 'week tow' or a calendar time"));
  auto csv = read_trajectory_csv(write("week.csv", "gps_week,gps_tow_s,x_m,y_m,z_m\n1e15,0,1,2,3\n"));
  ASSERT_FALSE(csv);
  EXPECT_THAT(csv.error().message, HasSubstr("/week.csv:2: time (GPS week 1000000000000000, 0 s) is out of range"));
}

TEST_F(RobustTrajectoryFuzzFinding, CsvWithGpsWeekButNoGpsTowColumnUsesTheOtherTimeColumns) {
  // Found by fuzz_trajectory (ASan/UBSan): "gps_week" without "gps_tow_s" next to the Septentrio time columns made
  // the reader index the row's cells at -1.
  auto r = read_trajectory_csv(write("week_only.csv", "gps_week,GpsCycle,GpsWeek,GpsToW [s],e_m,n_m,u_m\n"
                                                      "0,2,252,100.0,1,2,3\n0,2,252,101.0,4,5,6\n"));
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->trajectory.points.size(), 2u);
  EXPECT_EQ(r->trajectory.points[0].t, GpsTime::from_week_tow(2 * 1024 + 252, 100.0));
}

TEST_F(RobustTrajectoryFuzzFinding, NmeaWithAnImpossibleDateOrTimeIsAnError) {
  TrajectoryReadOptions o;
  o.nmea_date = "99999-01-01";
  auto date = read_nmea_gga(write("date.nmea", "$GPGGA,120000.00,5316.9,N,00903.1,W,1,8,1,20,M,55,M,,*4B\n"), o);
  ASSERT_FALSE(date);
  EXPECT_THAT(date.error().message, HasSubstr("nmea date '99999-01-01': expected YYYY-MM-DD"));
}

}  // namespace
}  // namespace pednav::io
