// SPDX-License-Identifier: BSD-2-Clause
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "core/geodesy.hpp"
#include "io/trajectory_io.hpp"

namespace pednav::io {
namespace {

using ::testing::HasSubstr;

std::string write_temp(const std::string& name, const std::string& content) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << content;
  return path;
}

// "$" + body + "*" + XOR checksum of body + newline.
std::string sentence(const std::string& body) {
  unsigned x = 0;
  for (char c : body) x ^= static_cast<unsigned char>(c);
  char buf[8];
  std::snprintf(buf, sizeof buf, "*%02X\n", x);
  return "$" + body + buf;
}

const std::string kRmc = sentence("GNRMC,153323.00,A,5316.82756,N,00903.47053,W,0.004,,041018,,,A");
const std::string kGga1 = sentence("GNGGA,153323.00,5316.82756,N,00903.47053,W,1,12,0.74,9.1,M,56.0,M,,");
const std::string kGga4 = sentence("GNGGA,153324.00,5316.82757,N,00903.47053,W,4,12,0.74,9.0,M,56.0,M,,");

TEST(NmeaReader, UtcToGpstAndEllipsoidalHeight) {
  const std::string path = write_temp("pednav_ok.nmea", kRmc + kGga1 + kGga4);
  auto f = read_trajectory(path, {});
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->format, "nmea");
  ASSERT_EQ(f->trajectory.points.size(), 2u);
  // 15:33:23 UTC on 2018-10-04 = 15:33:41 GPST.
  EXPECT_EQ(f->trajectory.points[0].t, GpsTime::from_calendar_gpst({2018, 10, 4, 15, 33, 41.0}));
  const Geodetic g = geodetic_from_ecef(f->trajectory.points[0].p);
  EXPECT_NEAR(g.lat * kRadToDeg, 53.0 + 16.82756 / 60.0, 1e-9);
  EXPECT_NEAR(g.lon * kRadToDeg, -(9.0 + 3.47053 / 60.0), 1e-9);
  EXPECT_NEAR(g.h_m, 9.1 + 56.0, 1e-6);
}

TEST(NmeaReader, QualityFilterAndChecksum) {
  std::string bad = kGga1;
  bad[20] = '9';  // corrupt a digit: checksum no longer matches
  const std::string path = write_temp("pednav_q.nmea", kRmc + bad + kGga4);
  TrajectoryReadOptions o;
  o.nmea_qualities = {4};
  auto f = read_trajectory(path, o);
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->trajectory.points.size(), 1u);
  EXPECT_EQ(f->skipped_checksum, 1);
  o.nmea_qualities = {5};
  auto none = read_trajectory(path, o);
  ASSERT_FALSE(none);
  EXPECT_THAT(none.error().message, HasSubstr("no GGA fix kept (1 with another quality, 1 bad checksums)"));
}

TEST(NmeaReader, NoDateIsAClearError) {
  const std::string path = write_temp("pednav_nodate.nmea", kGga1);
  auto f = read_trajectory(path, {});
  ASSERT_FALSE(f);
  EXPECT_THAT(f.error().message, HasSubstr("pednav_nodate.nmea:1: GGA has no date"));
  TrajectoryReadOptions o;
  o.nmea_date = "2018-10-04";
  auto ok = read_trajectory(path, o);
  ASSERT_TRUE(ok) << ok.error().message;
}

TEST(PosReader, CalendarLatLonAndWeekTowEcef) {
  const std::string a = write_temp(
      "pednav_a.pos",
      "% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix)\n"
      "%  GPST                  latitude(deg) longitude(deg)  height(m)   Q  ns\n"
      "2024/06/24 08:20:00.000   35.134699011  136.977575483   104.8619   1  42\n"
      "2024/06/24 08:20:01.000   35.134699008  136.977575479   104.8634   1  42\n");
  auto f = read_trajectory(a, {});
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->format, "pos");
  ASSERT_EQ(f->trajectory.points.size(), 2u);
  EXPECT_EQ(f->trajectory.points[0].t, GpsTime::from_calendar_gpst({2024, 6, 24, 8, 20, 0.0}));
  EXPECT_NEAR(geodetic_from_ecef(f->trajectory.points[0].p).h_m, 104.8619, 1e-6);
  const std::string b = write_temp("pednav_b.pos",
                                   "%  GPST          x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns\n"
                                   "2320 116400.000 -3817681.3807 3562839.9785 3650158.3760 1 12\n");
  auto g = read_trajectory(b, {});
  ASSERT_TRUE(g) << g.error().message;
  EXPECT_EQ(g->trajectory.points[0].t, GpsTime::from_week_tow(2320, 116400.0));
  EXPECT_NEAR(g->trajectory.points[0].p.x(), -3817681.3807, 1e-9);
  const std::string c = write_temp("pednav_c.pos", "%  GPST latitude(deg)\n2024/06/24 08:20:00.000 35.1 abc 1\n");
  auto bad = read_trajectory(c, {});
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("pednav_c.pos:2: expected three position numbers"));
}

TEST(CsvReader, PednavColumnsEcefAndLocal) {
  const std::string a = write_temp("pednav_sol.csv",
                                   "gps_week,gps_tow_s,lat_deg,lon_deg,h_m,x_m\n"
                                   "2021,400000.0,53.28,-9.06,60.0,1\n"
                                   "2021,400001.0,,,,\n"
                                   "2021,400002.0,53.28001,-9.06,60.0,1\n");
  auto f = read_trajectory(a, {});
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->trajectory.points.size(), 2u);
  EXPECT_EQ(f->skipped_empty, 1);
  const std::string b = write_temp("pednav_loc.csv", "gps_week,gps_tow_s,e_m,n_m,u_m\n0,1.0,1,2,3\n");
  auto g = read_trajectory(b, {});
  ASSERT_TRUE(g) << g.error().message;
  EXPECT_EQ(g->trajectory.frame, eval::Frame::kLocalEnu);
}

TEST(CsvReader, SolutionSigmasAreReadWhenPresent) {
  const std::string a = write_temp("pednav_sigma.csv",
                                   "gps_week,gps_tow_s,lat_deg,lon_deg,h_m,sd_n_m,sd_e_m,sd_d_m\n"
                                   "2021,400000.0,53.28,-9.06,60.0,0.5,0.25,1.5\n"
                                   "2021,400001.0,53.28,-9.06,60.0,,,\n");
  auto f = read_trajectory(a, {});
  ASSERT_TRUE(f) << f.error().message;
  ASSERT_EQ(f->trajectory.points.size(), 2u);
  const Eigen::Vector3d sd = f->trajectory.points[0].sd_enu_m;  // E, N, U
  EXPECT_DOUBLE_EQ(sd.x(), 0.25);
  EXPECT_DOUBLE_EQ(sd.y(), 0.5);
  EXPECT_DOUBLE_EQ(sd.z(), 1.5);
  EXPECT_TRUE(std::isnan(f->trajectory.points[1].sd_enu_m.x()));  // empty cells: unknown
}

TEST(CsvReader, BadInputsNameFileAndLine) {
  auto cols = read_trajectory(write_temp("pednav_nocols.csv", "time,a,b\n1,2,3\n"), {});
  ASSERT_FALSE(cols);
  EXPECT_THAT(cols.error().message, HasSubstr("pednav_nocols.csv:1: header lacks time columns"));
  auto pos = read_trajectory(write_temp("pednav_nopos.csv", "gps_week,gps_tow_s,a\n1,2,3\n"), {});
  ASSERT_FALSE(pos);
  EXPECT_THAT(pos.error().message, HasSubstr("header lacks position columns"));
  auto back = read_trajectory(
      write_temp("pednav_back.csv", "gps_week,gps_tow_s,x_m,y_m,z_m\n1,5,6.4e6,0,0\n1,4,6.4e6,0,0\n"), {});
  ASSERT_FALSE(back);
  EXPECT_THAT(back.error().message, HasSubstr("pednav_back.csv:3: time"));
  EXPECT_THAT(back.error().message, HasSubstr("is before the previous"));
  auto num = read_trajectory(write_temp("pednav_num.csv", "gps_week,gps_tow_s,x_m,y_m,z_m\n1,5,6.4e6,zz,0\n"), {});
  ASSERT_FALSE(num);
  EXPECT_THAT(num.error().message, HasSubstr("pednav_num.csv:2: expected 3 numbers in the position columns"));
  auto empty = read_trajectory(write_temp("pednav_empty.csv", ""), {});
  ASSERT_FALSE(empty);
  EXPECT_THAT(empty.error().message, HasSubstr("pednav_empty.csv: file is empty"));
  auto missing = read_trajectory("/nonexistent/ref.csv", {});
  ASSERT_FALSE(missing);
  EXPECT_THAT(missing.error().message, HasSubstr("/nonexistent/ref.csv: cannot open file"));
}

}  // namespace
}  // namespace pednav::io
