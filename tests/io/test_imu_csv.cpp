// SPDX-License-Identifier: BSD-2-Clause
// IMU CSV reader: time bases, units, axes/mounting, messy-log handling and the messages of bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "core/geodesy.hpp"
#include "io/config.hpp"
#include "io/imu_csv.hpp"
#include "tests/support/data.hpp"

namespace pednav::io {
namespace {

using ::testing::HasSubstr;

constexpr double kTol = 1e-9;

// A still log at 100 Hz: header + n rows "t, gx, gy, gz, ax, ay, az" with f = (0, 0, -g_unit).
std::string still_csv(int n, double g_value = 9.80665, double t0 = 0.0) {
  std::ostringstream os;
  os << std::setprecision(12) << "t,gx,gy,gz,ax,ay,az\n";
  for (int i = 0; i < n; ++i) os << t0 + i * 0.01 << ",0.001,-0.002,0.003,0.01,0.02," << -g_value << "\n";
  return os.str();
}

ImuFormat basic() {
  ImuFormat f;
  f.name = "test";
  f.gyro_columns = {1, 2, 3};
  f.accel_columns = {4, 5, 6};
  return f;
}

Expected<ImuLog> parse(const std::string& text, const ImuFormat& f) {
  return parse_imu_csv(text.data(), text.size(), "imu.csv", f);
}

TEST(ImuCsv, RelativeTimeWithoutEpochMapsToWeekZero) {
  auto log = parse(still_csv(200, 9.80665, 12.5), basic());
  ASSERT_TRUE(log) << log.error().message;
  EXPECT_EQ(log->samples.size(), 200u);
  EXPECT_EQ(log->samples.front().t.week(), 0);
  EXPECT_NEAR(log->samples.front().t.tow_s(), 12.5, kTol);
  EXPECT_NEAR(log->report.rate_hz, 100.0, 1e-6);
  EXPECT_NEAR(log->report.rest_f_norm_mps2, std::sqrt(0.01 * 0.01 + 0.02 * 0.02 + 9.80665 * 9.80665), 1e-9);
}

TEST(ImuCsv, TimeBases) {
  ImuFormat f = basic();
  f.time_base = "gps_sow";
  f.gps_week = 2100;
  auto sow = parse(still_csv(100, 9.80665, 345600.0), f);
  ASSERT_TRUE(sow) << sow.error().message;
  EXPECT_EQ(sow->samples.front().t, GpsTime::from_week_tow(2100, 345600.0));
  f = basic();
  f.time_base = "gpst_unix";  // seconds since 1970 in the GPS time scale
  auto unix = parse(still_csv(100, 9.80665, 315964800.0 + 604800.0 * 3 + 10.0), f);
  ASSERT_TRUE(unix) << unix.error().message;
  EXPECT_EQ(unix->samples.front().t, GpsTime::from_week_tow(3, 10.0));
  f = basic();
  f.start_epoch = GpsTime::from_week_tow(2000, 100.0);
  auto rel = parse(still_csv(100, 9.80665, 1.0), f);
  ASSERT_TRUE(rel) << rel.error().message;
  EXPECT_EQ(rel->samples.front().t, GpsTime::from_week_tow(2000, 101.0));
  f = basic();
  f.time_base = "index";
  f.index_rate_hz = 250.0;
  auto idx = parse(still_csv(100), f);
  ASSERT_TRUE(idx) << idx.error().message;
  EXPECT_NEAR(idx->samples[10].t.seconds(), 10.0 / 250.0, kTol);
}

TEST(ImuCsv, UnitsSignsAndMounting) {
  // deg/s and g, y axes flipped, mounting yaw 90 deg: body x = -sensor y... (R_b_s = Rz(90)).
  std::string text = "h\n";
  for (int i = 0; i < 100; ++i) text += std::to_string(i * 0.01) + ",10,20,30,0.1,0.2,-1\n";
  ImuFormat f = basic();
  f.gyro_unit = "deg_per_s";
  f.accel_unit = "g";
  f.gyro_signs = Eigen::Vector3d(1, -1, 1);
  f.accel_signs = Eigen::Vector3d(1, -1, 1);
  f.R_b_s = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  auto log = parse(text, f);
  ASSERT_TRUE(log) << log.error().message;
  const auto& s = log->samples[5];
  // sensor: w = (10, -20, 30) deg/s; Rz(90) maps (x, y, z) -> (-y, x, z).
  EXPECT_NEAR(s.omega_ib_b.x(), 20 * kDegToRad, kTol);
  EXPECT_NEAR(s.omega_ib_b.y(), 10 * kDegToRad, kTol);
  EXPECT_NEAR(s.omega_ib_b.z(), 30 * kDegToRad, kTol);
  EXPECT_NEAR(s.f_ib_b.x(), 0.2 * 9.80665, kTol);
  EXPECT_NEAR(s.f_ib_b.z(), -9.80665, kTol);
}

TEST(ImuCsv, IncrementsBecomeRates) {
  std::string text = "h\n";
  for (int i = 0; i < 100; ++i) text += std::to_string(i * 0.01) + ",0.001,0,0,0,0,-0.0980665\n";
  ImuFormat f = basic();
  f.gyro_unit = "rad";
  f.accel_unit = "mps";
  auto log = parse(text, f);
  ASSERT_TRUE(log) << log.error().message;
  EXPECT_NEAR(log->samples[7].omega_ib_b.x(), 0.1, 1e-9);
  EXPECT_NEAR(log->samples[7].f_ib_b.z(), -9.80665, 1e-9);
}

TEST(ImuCsv, DuplicatesDroppedAndCountedGapsBridgedNanReported) {
  std::string text = still_csv(300);
  std::istringstream in(text);
  std::string line, out;
  int n = 0;
  while (std::getline(in, line)) {
    out += line + "\n";
    if (n == 10 || n == 20) out += line + "\n";                          // exact duplicates
    if (n == 30) out += line.substr(0, line.find(',')) + ",9,9,9,0,0,-9.8\n";  // same time, other values
    if (n == 40) out += "0.405,nan,0,0,0,0,-9.8\n0.406,,0,0,0,0,-9.8\n";  // NaN and empty fields
    ++n;
  }
  // Remove rows 100..102 -> a 40 ms gap (bridged; limit 0.1 s).
  const auto a = out.find("\n1,"), b = out.find("\n1.03,");
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  out.erase(a, b - a);
  auto log = parse(out, basic());
  ASSERT_TRUE(log) << log.error().message;
  const auto& r = log->report;
  EXPECT_EQ(r.duplicates_dropped, 3);
  EXPECT_EQ(r.duplicates_differing, 1);
  EXPECT_EQ(r.bad_rows, 2);
  EXPECT_EQ(r.first_bad_line, 45);  // header + 40 rows + 3 inserted duplicates + 1
  EXPECT_EQ(r.gaps, 1);
  EXPECT_NEAR(r.longest_gap_s, 0.04, 1e-9);
  ASSERT_GE(r.warnings.size(), 3u);
  std::string all;
  for (const auto& w : r.warnings) all += w + "\n";
  EXPECT_THAT(all, HasSubstr("3 duplicate time stamps dropped (1 with differing values)"));
  EXPECT_THAT(all, HasSubstr("first at imu.csv:45: column 1 is 'nan' (expected a finite number)"));
  EXPECT_THAT(all, HasSubstr("1 gaps"));
  // The same gap with a 30 ms limit is an error naming the line.
  ImuFormat f = basic();
  f.max_gap_s = 0.03;
  auto bad = parse(out, f);
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("gap of 0.0400 s exceeds the bridging limit max_gap_s = 0.03 s"));
  EXPECT_THAT(bad.error().message, HasSubstr("imu.csv:"));
}

TEST(ImuCsv, OutOfOrderTimeIsAnErrorWithFileAndLine) {
  std::string text = still_csv(100);
  text.insert(text.find("\n0.05,") + 1, "0.035,0,0,0,0,0,-9.8\n");
  auto log = parse(text, basic());
  ASSERT_FALSE(log);
  EXPECT_THAT(log.error().message, HasSubstr("imu.csv:7: time 0.035000 s is not after the previous 0.040000 s"));
}

// A Crista-class accelerometer's 30 mg turn-on bias + 1 % scale error can put |f| at rest 0.7 m/s^2 from 9.81
// (forest_walk seed 11: 10.52): that log loads, with a warning naming the value; a unit mistake does not.
TEST(ImuCsv, LargeAccelerometerBiasWarnsButAUnitMistakeFails) {
  auto biased = parse(still_csv(200, 10.52), basic());
  ASSERT_TRUE(biased) << biased.error().message;
  std::string all;
  for (const auto& w : biased->report.warnings) all += w + "\n";
  EXPECT_THAT(all, HasSubstr("specific force at rest is 10.52 m/s^2 (0.71 from 9.81"));
  auto nominal = parse(still_csv(200, 9.9), basic());
  ASSERT_TRUE(nominal);
  for (const auto& w : nominal->report.warnings) EXPECT_THAT(w, ::testing::Not(HasSubstr("specific force"))) << w;
  auto ft = parse(still_csv(200, 32.17), basic());  // ft/s^2 read as m/s^2
  ASSERT_FALSE(ft);
  EXPECT_THAT(ft.error().message, HasSubstr("specific force at rest is 32.17"));
  ImuFormat tight = basic();
  tight.rest_tolerance_mps2 = 0.5;
  EXPECT_FALSE(parse(still_csv(200, 10.52), tight)) << "the configured tolerance is the limit";
}

TEST(ImuCsv, UnitMistakesNameTheSettingThatIsProbablyWrong) {
  auto g_as_mps2 = parse(still_csv(200, 1.0), basic());
  ASSERT_FALSE(g_as_mps2);
  EXPECT_THAT(g_as_mps2.error().message, HasSubstr("specific force at rest is 1"));
  EXPECT_THAT(g_as_mps2.error().message, HasSubstr("accel.unit is probably g"));
  ImuFormat g = basic();
  g.accel_unit = "g";
  auto mps2_as_g = parse(still_csv(200), g);
  ASSERT_FALSE(mps2_as_g);
  EXPECT_THAT(mps2_as_g.error().message, HasSubstr("accel.unit is probably mps2, not g"));
  std::string text = still_csv(200);
  text += "2.0,300,0,0,0,0,-9.8\n";  // 300 "rad/s": a deg/s log read as rad/s
  auto deg = parse(text, basic());
  ASSERT_FALSE(deg);
  EXPECT_THAT(deg.error().message, HasSubstr("gyro.unit is probably deg_per_s"));
}

TEST(ImuCsv, SaturationAndBadFormat) {
  std::string text = still_csv(200);
  text += "2.0,5.2359,0,0,0,0,-9.8\n2.01,0,0,0,0,0,-9.8\n";  // x gyro at 300 deg/s
  ImuFormat f = basic();
  f.gyro_full_scale = 300.0 * kDegToRad;
  auto log = parse(text, f);
  ASSERT_TRUE(log) << log.error().message;
  EXPECT_EQ(log->report.saturated_samples, 1);
  f.time_base = "gps_sow";
  f.gyro_unit = "furlongs";
  auto bad = parse(text, f);
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("time.gps_week: required for time.base gps_sow"));
  EXPECT_THAT(bad.error().message, HasSubstr("gyro.unit: expected one of"));
  auto missing = read_imu_csv("/nonexistent/imu.csv", basic());
  ASSERT_FALSE(missing);
  EXPECT_THAT(missing.error().message, HasSubstr("/nonexistent/imu.csv: cannot open IMU log"));
  auto short_rows = parse("h\n0,1,2\n0.01,1,2\n", basic());
  ASSERT_FALSE(short_rows);
  EXPECT_THAT(short_rows.error().message, HasSubstr("only 3 columns (expected at least 7)"));
}

// An optional stance-label column (zupt.detector labels): one 0/1 per kept sample, aligned with the samples when
// rows are dropped; any other value makes the row bad, counted, with the reason.
TEST(ImuCsv, StanceLabelColumnStaysAlignedAndOtherValuesAreBadRows) {
  std::ostringstream os;
  os << "t,gx,gy,gz,ax,ay,az,label\n";
  for (int i = 0; i < 200; ++i) {
    os << i * 0.01 << ",0,0,0,0,0,-9.80665," << (i % 3 == 0 ? "1" : "0") << "\n";
    if (i == 50) os << i * 0.01 << ",0,0,0,0,0,-9.80665,0\n";  // duplicate time: dropped with its label
  }
  os << "2.0,0,0,0,0,0,-9.80665,2\n2.01,0,0,0,0,0,-9.80665,1\n";
  ImuFormat f = basic();
  f.stance_column = 7;
  auto log = parse(os.str(), f);
  ASSERT_TRUE(log) << log.error().message;
  ASSERT_EQ(log->stance.size(), log->samples.size());
  ASSERT_EQ(log->samples.size(), 201u);
  for (int i = 0; i < 200; ++i) EXPECT_EQ(log->stance[static_cast<size_t>(i)], i % 3 == 0 ? 1 : 0) << i;
  EXPECT_EQ(log->stance.back(), 1);
  EXPECT_EQ(log->report.bad_rows, 1);
  std::string all;
  for (const auto& w : log->report.warnings) all += w + "\n";
  EXPECT_THAT(all, HasSubstr("imu.csv:203: stance column 7 is '2' (expected 0 or 1)"));
  // Without the column in the format, no labels are read.
  auto plain = parse(os.str(), basic());
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_TRUE(plain->stance.empty());
  // In a config: stance.column must be a column index.
  auto cfg = parse_run_config(
      "mode: ins\nimu:\n  file: a.csv\n  format:\n    gyro: {columns: [1, 2, 3]}\n    accel: {columns: [4, 5, 6]}\n"
      "    stance: {column: -1}\n",
      "cfg.yaml", "/d");
  ASSERT_FALSE(cfg);
  EXPECT_THAT(cfg.error().message, HasSubstr("imu.format.stance.column"));
}

// Magnetometer columns (initial.heading: magnetometer): converted to µT, signed and mounted like the gyro, kept
// aligned with the samples (a duplicate time drops its field too); a bad cell makes the row bad.
TEST(ImuCsv, MagnetometerColumnsInMicroteslaInTheBodyFrameAlignedWithTheSamples) {
  std::ostringstream os;
  os << "t,gx,gy,gz,ax,ay,az,mx,my,mz\n";
  for (int i = 0; i < 200; ++i) {
    os << i * 0.01 << ",0,0,0,0,0,-9.80665,0.2," << 0.001 * i << ",0.4\n";
    if (i == 50) os << i * 0.01 << ",0,0,0,0,0,-9.80665,9,9,9\n";  // duplicate time: dropped with its field
  }
  os << "2.0,0,0,0,0,0,-9.80665,0.2,x,0.4\n";
  ImuFormat f = basic();
  f.mag_columns = {7, 8, 9};
  f.mag_signs = Eigen::Vector3d(1, -1, 1);
  f.mag_scale_to_ut = 100.0;  // gauss
  f.R_b_s = Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();  // (x, y, z) -> (-y, x, z)
  auto log = parse(os.str(), f);
  ASSERT_TRUE(log) << log.error().message;
  ASSERT_EQ(log->samples.size(), 200u);
  ASSERT_EQ(log->mag_b.size(), log->samples.size());
  for (const int i : {0, 50, 51, 199}) {
    // sensor (20, -0.1 i, 40) µT -> body (0.1 i, 20, 40) µT
    EXPECT_NEAR(log->mag_b[static_cast<size_t>(i)].x(), 0.1 * i, 1e-9) << i;
    EXPECT_NEAR(log->mag_b[static_cast<size_t>(i)].y(), 20.0, 1e-9) << i;
    EXPECT_NEAR(log->mag_b[static_cast<size_t>(i)].z(), 40.0, 1e-9) << i;
  }
  EXPECT_EQ(log->report.bad_rows, 1);
  std::string all;
  for (const auto& w : log->report.warnings) all += w + "\n";
  EXPECT_THAT(all, HasSubstr("imu.csv:203: column 8 is 'x' (expected a finite number)"));
  EXPECT_TRUE(parse(os.str(), basic())->mag_b.empty());  // no mag columns in the format: nothing read
  // In a config: units, three columns, signs.
  auto with_mag = [](const std::string& mag_line) {
    return parse_run_config("mode: ins\nimu:\n  file: a.csv\n  format:\n    gyro: {columns: [1, 2, 3]}\n"
                            "    accel: {columns: [4, 5, 6]}\n" + mag_line,
                            "cfg.yaml", "/d");
  };
  auto cfg = with_mag("    mag: {columns: [7, 8, 9], unit: nt, signs: [1, 1, -1]}\n");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->imu.format.mag_columns[2], 9);
  EXPECT_DOUBLE_EQ(cfg->imu.format.mag_scale_to_ut, 1e-3);
  EXPECT_EQ(cfg->imu.format.mag_signs.z(), -1.0);
  auto bad = with_mag("    mag: {columns: [7, 8], unit: tesla, signs: [1, 2, 1]}\n");
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("imu.format.mag.columns: expected 3 column indices, got 2"));
  EXPECT_THAT(bad.error().message, HasSubstr("imu.format.mag.unit: expected one of"));
  EXPECT_THAT(bad.error().message, HasSubstr("imu.format.mag: signs must each be 1 or -1"));
  auto missing = with_mag("    mag: {unit: ut}\n");
  ASSERT_FALSE(missing);
  EXPECT_THAT(missing.error().message, HasSubstr("imu.format.mag.columns: required key is missing"));
}

// initial.heading / declination_deg: one source of the initial heading.
TEST(ImuConfig, MagnetometerHeadingKeys) {
  const std::string base = "mode: ins\nimu:\n  file: a.csv\n  format: lord_sensorconnect\n  spec: gx5_25\n";
  auto ok = parse_run_config(base + "initial: {lat_deg: 45, lon_deg: 0, h_m: 0, heading: magnetometer, declination_deg: -3.5}\n",
                             "cfg.yaml", "/d");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_TRUE(ok->initial.heading_from_magnetometer);
  EXPECT_NEAR(ok->initial.declination_rad, -3.5 * kDegToRad, 1e-15);
  EXPECT_EQ(ok->imu.format.mag_columns[0], 7);  // the LORD preset reads its magnetometer
  EXPECT_DOUBLE_EQ(ok->imu.format.mag_scale_to_ut, 100.0);
  auto both = parse_run_config(base + "initial: {heading: magnetometer, yaw_deg: 10}\n", "cfg.yaml", "/d");
  ASSERT_FALSE(both);
  EXPECT_THAT(both.error().message, HasSubstr("initial.heading: magnetometer and yaw_deg both set the initial heading"));
  auto decl = parse_run_config(base + "initial: {yaw_deg: 10, declination_deg: 2}\n", "cfg.yaml", "/d");
  ASSERT_FALSE(decl);
  EXPECT_THAT(decl.error().message, HasSubstr("initial.declination_deg: only used with heading: magnetometer"));
  auto value = parse_run_config(base + "initial: {heading: compass}\n", "cfg.yaml", "/d");
  ASSERT_FALSE(value);
  EXPECT_THAT(value.error().message, HasSubstr("initial.heading: expected one of"));
}

TEST(ImuFormatPresets, EmbeddedTextEqualsDatasetsFilesAndParses) {
  for (const auto& name : imu_format_preset_names()) {
    std::ifstream in(test::source_path("datasets/imu_formats/" + name + ".yaml"));
    ASSERT_TRUE(in) << name;
    std::stringstream ss;
    ss << in.rdbuf();
    EXPECT_EQ(ss.str(), imu_format_preset_yaml(name)) << name;
    auto f = imu_format_preset(name);
    ASSERT_TRUE(f) << f.error().message;
    EXPECT_TRUE(f->problems().empty()) << name;
  }
  auto unknown = imu_format_preset("nope");
  ASSERT_FALSE(unknown);
  EXPECT_THAT(unknown.error().message, HasSubstr("unknown IMU format preset 'nope' (expected one of pyshoe"));
}

TEST(ImuConfig, PresetAndInlineFormatAndSpec) {
  auto cfg = parse_run_config(
      "mode: ins\nimu:\n  file: a.csv\n  format: xio_ngimu\n  spec: gx5_25\n", "cfg.yaml", "/d");
  ASSERT_TRUE(cfg) << cfg.error().message;
  EXPECT_EQ(cfg->imu.format.gyro_unit, "deg_per_s");
  EXPECT_NEAR(cfg->imu.format.gyro_full_scale, 2000 * kDegToRad, 1e-9);
  EXPECT_NEAR(cfg->imu.spec.gyro_arw, 0.005 * kDegToRad, 1e-12);
  auto inl = parse_run_config(
      "mode: ins\nimu:\n  file: a.csv\n  format:\n    delimiter: tab\n    time: {base: index, rate_hz: 100}\n"
      "    gyro: {columns: [0, 1, 2], unit: deg_per_s, signs: [1, -1, -1]}\n    accel: {columns: [3, 4, 5], unit: g}\n"
      "    mounting_rpy_deg: [180, 0, 0]\n  spec:\n    preset: hg1700\n    gyro_arw_deg_per_sqrt_hr: 0.5\n"
      "    accel_bias_instability_mg: 2\n",
      "cfg.yaml", "/d");
  ASSERT_TRUE(inl) << inl.error().message;
  EXPECT_EQ(inl->imu.format.delimiter, '\t');
  EXPECT_EQ(inl->imu.format.time_base, "index");
  EXPECT_EQ(inl->imu.format.gyro_signs.y(), -1.0);
  EXPECT_NEAR(inl->imu.format.R_b_s(1, 1), -1.0, 1e-12);
  EXPECT_NEAR(inl->imu.spec.gyro_arw, 0.5 * kDegToRad / 60.0, 1e-12);
  EXPECT_NEAR(inl->imu.spec.accel_bias_instability, 2e-3 * 9.80665, 1e-12);
  EXPECT_NEAR(inl->imu.spec.gyro_bias_instability, 1.0 * kDegToRad / 3600.0, 1e-15);  // from the hg1700 base
}

TEST(ImuConfig, BadFormatAndSpecKeysAreReportedWithPaths) {
  auto cfg = parse_run_config(
      "mode: ins\nimu:\n  file: a.csv\n  format:\n    time: {base: gps_sow}\n    gyro: {columns: [1, 2], unit: rpm}\n"
      "  spec:\n    gyro_arw: 0.3\n    gyro_bias_instability_deg_per_hr: 5\n",
      "cfg.yaml", "/d");
  ASSERT_FALSE(cfg);
  const std::string& m = cfg.error().message;
  EXPECT_THAT(m, HasSubstr("imu.format.time.gps_week: required key is missing (base gps_sow)"));
  EXPECT_THAT(m, HasSubstr("imu.format.gyro.columns: expected 3 column indices, got 2"));
  EXPECT_THAT(m, HasSubstr("imu.format.gyro.unit: expected one of"));
  EXPECT_THAT(m, HasSubstr("imu.spec.gyro_arw: unknown key"));
  EXPECT_THAT(m, HasSubstr("imu.spec.gyro_bias_tau_s: must be > 0"));
  auto preset = parse_run_config("mode: ins\nimu:\n  file: a.csv\n  format: nope\n  spec: tactical\n", "cfg.yaml", "/d");
  ASSERT_FALSE(preset);
  EXPECT_THAT(preset.error().message, HasSubstr("imu.format: unknown IMU format preset 'nope'"));
  EXPECT_THAT(preset.error().message, HasSubstr("imu.spec: unknown IMU spec preset 'tactical'"));
}

}  // namespace
}  // namespace pednav::io
