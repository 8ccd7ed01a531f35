// SPDX-License-Identifier: BSD-2-Clause
// RINEX reading through the RTKLIB adapter (gnss/rtklib/rinex): inputs found by fuzz/fuzz_rinex (issue 11,
// docs/robustness.md). A date far outside the GPS time range in a navigation or observation record overflowed the
// nanosecond count (UBSan); records dated before the GPS epoch or after 2106 are now dropped (and counted). Meaningful under the ASan + UBSan build.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "gnss/rtklib/rinex.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::gnss {
namespace {

using ::testing::HasSubstr;

// One GPS ephemeris (RINEX 3.04); its GPS week field is "2.295000000000E+03".
const std::string kNav =
    "     3.04           N: GNSS NAV DATA    M                   RINEX VERSION / TYPE\n"
    "GPSA   1.1176E-08  7.4506E-09 -5.9605E-08 -5.9605E-08       IONOSPHERIC CORR    \n"
    "GPSB   1.1059E+05  0.0000E+00 -2.6214E+05  1.9661E+05       IONOSPHERIC CORR    \n"
    "    18                                                      LEAP SECONDS        \n"
    "                                                            END OF HEADER       \n"
    "G01 2024 01 01 02 00 00 1.234567890123E-04 1.136868377216E-12 0.000000000000E+00\n"
    "     4.500000000000E+01-3.200000000000E+01 4.300000000000E-09 1.200000000000E+00\n"
    "    -1.600000000000E-06 5.100000000000E-03 8.200000000000E-06 5.153000000000E+03\n"
    "     1.728000000000E+05-1.100000000000E-07 1.200000000000E+00 3.700000000000E-08\n"
    "     9.700000000000E-01 2.300000000000E+02 8.000000000000E-01-8.100000000000E-09\n"
    "    -3.100000000000E-10 1.000000000000E+00 2.295000000000E+03 0.000000000000E+00\n"
    "     2.000000000000E+00 0.000000000000E+00-1.100000000000E-08 4.500000000000E+01\n"
    "     1.700000000000E+05 4.000000000000E+00\n";

// One RINEX 3.04 observation epoch of 5 satellites (GPS, GLONASS, Galileo, BeiDou).
const std::string kObs =
    "     3.04           OBSERVATION DATA    M                   RINEX VERSION / TYPE\n"
    "pednav seed                             20240101 000000 UTC PGM / RUN BY / DATE \n"
    "TEST                                                        MARKER NAME         \n"
    "  3822100.0000  -609600.0000  5083000.0000                  APPROX POSITION XYZ \n"
    "G    4 C1C L1C D1C S1C                                      SYS / # / OBS TYPES \n"
    "R    4 C1C L1C D1C S1C                                      SYS / # / OBS TYPES \n"
    "E    4 C1C L1C D1C S1C                                      SYS / # / OBS TYPES \n"
    "C    4 C2I L2I D2I S2I                                      SYS / # / OBS TYPES \n"
    "  2024     1     1     0     0    0.0000000     GPS         TIME OF FIRST OBS   \n"
    " R07  1 R08 -4                                              GLONASS SLOT / FRQ #\n"
    "                                                            END OF HEADER       \n"
    "> 2024 01 01 00 00  0.0000000  0  5\n"
    "G01  20123456.789   105789456.123 7     -1234.567          45.000  \n"
    "G07  20124456.789   105789457.123 7     -1233.567          44.000  \n"
    "R07  20125456.789   105789458.123 7     -1232.567          43.000  \n"
    "E11  20126456.789   105789459.123 7     -1231.567          42.000  \n"
    "C30  20127456.789   105789460.123 7     -1230.567          41.000  \n";

// This process's temporary folder, made once.
const std::string& kTempDir() {
  static const std::string dir = test::temp_dir("robust_rinex");
  return dir;
}

std::string write(const std::string& name, const std::string& text) {
  const std::string p = (std::filesystem::path(kTempDir()) / name).string();
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

TEST(RobustRinexFuzzFinding, EphemerisWithAnAbsurdWeekIsDroppedNotOverflowed) {
  auto good = read_rinex_nav({write("good.rnx", kNav)});
  ASSERT_TRUE(good) << good.error().message;
  ASSERT_EQ(good->kepler.size(), 1u);
  EXPECT_EQ(good->kepler[0].week, 2295);
  std::string text = kNav;
  text.replace(text.find("2.295000000000E+03"), 18, "9.999990000000E+05");  // GPS week 999999: year ~21000
  auto bad = read_rinex_nav({write("bad_week.rnx", text)});
  ASSERT_TRUE(bad) << bad.error().message;  // RTKLIB read it; pednav drops the unusable ephemeris
  EXPECT_TRUE(bad->kepler.empty());
}

TEST(RobustRinexFuzzFinding, ObservationEpochOutsideRtklibsYearRangeIsDroppedAndCounted) {
  const SystemSelection all{true, true, true, true, true};
  auto good = read_rinex_obs(write("good.obs", kObs), all);
  ASSERT_TRUE(good) << good.error().message;
  ASSERT_EQ(good->epochs.size(), 1u);
  EXPECT_EQ(good->epochs[0].sats.size(), 5u);
  std::string text = kObs;
  text.replace(text.find("> 2024"), 6, "> 2150");  // RTKLIB: 1970-01-01, before the GPS epoch
  auto bad = read_rinex_obs(write("year.obs", text), all);
  ASSERT_FALSE(bad);
  EXPECT_THAT(bad.error().message, HasSubstr("/year.obs: no usable observation epoch"));
}

TEST(RobustRinexFuzzFinding, OutOfRangeSnrFieldIsNotAMemoryError) {
  // RTKLIB converts the SNR field to uint16_t without a range check (undefined behaviour in C, 0 or a wrapped value
  // on x86; docs/robustness.md): the reader must still return finite data for the other fields.
  std::string text = kObs;
  text.replace(text.find("45.000"), 6, "-7e+13");
  auto r = read_rinex_obs(write("snr.obs", text), SystemSelection{});
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_FALSE(r->epochs.empty());
  EXPECT_DOUBLE_EQ(r->epochs[0].sats[0].pseudorange_m, 20123456.789);
}

TEST(RobustRinexFuzzFinding, EpochRecordsAFewMillisecondsApartComeOutSortedWithOneRecordPerSatellite) {
  // RTKLIB's sortobs treats times closer than its DTTOL as one time and then orders by satellite, so these records
  // came back interleaved (0.008, 0.000, 0.008, …) and the reader returned epochs out of order.
  const std::string header = kObs.substr(0, kObs.find("> 2024"));
  const std::string text = header +
                           "> 2024 01 01 00 00  0.0080000  0  2\n"
                           "G01  20123456.789   105789456.123 7     -1234.567          45.000  \n"
                           "G07  20124456.789   105789457.123 7     -1233.567          44.000  \n"
                           "> 2024 01 01 00 00  0.0000000  0  2\n"
                           "G01  20123457.789   105789456.123 7     -1234.567          45.000  \n"
                           "G07  20124457.789   105789457.123 7     -1233.567          44.000  \n"
                           "> 2024 01 01 00 00  0.0080001  0  1\n"
                           "G01  20123458.789   105789456.123 7     -1234.567          45.000  \n";
  auto r = read_rinex_obs(write("interleaved.obs", text), SystemSelection{});
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r->epochs.size(), 2u);
  EXPECT_TRUE(r->epochs[0].time < r->epochs[1].time);
  EXPECT_NEAR(r->epochs[1].time - r->epochs[0].time, 0.008, 1e-6);
  for (const auto& e : r->epochs) {
    ASSERT_EQ(e.sats.size(), 2u);
    EXPECT_FALSE(e.sats[0].sat == e.sats[1].sat);
  }
  EXPECT_DOUBLE_EQ(r->epochs[0].sats[0].pseudorange_m, 20123457.789);  // the 0.000 record
  EXPECT_EQ(r->stats.duplicate_records, 1);                              // G01 at 0.0080001: the first kept
}

}  // namespace
}  // namespace pednav::gnss
