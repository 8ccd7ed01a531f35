// SPDX-License-Identifier: BSD-2-Clause
// io/report.*: numeric CSV tables, base64, and report.html of a small synthetic run folder (self-contained:
// every plot an SVG data URI; sections for the evaluation, trajectory, errors, satellites, ZUPTs, outages).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/geodesy.hpp"
#include "io/report.hpp"
#include "tests/io/report_fixture.hpp"
#include "tests/sim/fixtures.hpp"

namespace pednav::io {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(Report, Base64KnownVectors) {  // RFC 4648 section 10
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
}

TEST(Report, CsvTableReadsNumbersAndNamesBadLines) {
  const std::string d = test::temp_dir("csv_table");
  {
    std::ofstream f(d + "/a.csv");
    f << "a,b,c\n1,2.5,\n3,x,4\n";
  }
  auto t = read_csv_table(d + "/a.csv");
  ASSERT_TRUE(t.has_value()) << t.error().message;
  EXPECT_EQ(t->rows, 2u);
  ASSERT_NE(t->column("b"), nullptr);
  EXPECT_DOUBLE_EQ((*t->column("b"))[0], 2.5);
  EXPECT_TRUE(std::isnan((*t->column("b"))[1]));
  EXPECT_TRUE(std::isnan((*t->column("c"))[0]));
  EXPECT_EQ(t->column("zz"), nullptr);
  {
    std::ofstream f(d + "/bad.csv");
    f << "a,b\n1,2\n1,2,3\n";
  }
  auto bad = read_csv_table(d + "/bad.csv");
  ASSERT_FALSE(bad.has_value());
  EXPECT_THAT(bad.error().message, HasSubstr("bad.csv:3: 3 cells, the header has 2 columns"));
}

TEST(Report, EmptyFolderIsAnError) {
  const std::string d = test::temp_dir("report_empty");
  auto r = run_report_command(d);
  ASSERT_FALSE(r.has_value());
  EXPECT_THAT(r.error().message, HasSubstr("nothing to report"));
  EXPECT_THAT(run_report_command(d + "/missing").error().message, HasSubstr("not a folder"));
}

TEST(Report, RunFolderGivesSelfContainedHtmlWithEveryPlot) {
  const std::string d = test::temp_dir("report_run");
  test::write_report_fixture(d);
  auto r = run_report_command(d);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  for (const auto& w : r->warnings) ADD_FAILURE() << "warning: " << w;
  // trajectory, horizontal error, CDF, north +-3 sigma, east +-3 sigma, satellites, ZUPT, outage RMS.
  EXPECT_EQ(r->plots, test::kReportFixturePlots);
  const std::string html = test::read_text(d + "/report.html");
  size_t n_img = 0;
  for (size_t p = html.find("data:image/svg+xml;base64,"); p != std::string::npos;
       p = html.find("data:image/svg+xml;base64,", p + 1)) {
    ++n_img;
  }
  EXPECT_EQ(n_img, static_cast<size_t>(test::kReportFixturePlots));
  EXPECT_THAT(html, HasSubstr("seed 004 Tables 1-2"));
  EXPECT_THAT(html, HasSubstr("<td>RTS smoothed</td>"));
  EXPECT_THAT(html, HasSubstr("Outage study: partial outages, 3 satellites kept"));
  EXPECT_THAT(html, HasSubstr("Per-segment statistics"));
  // The first screen answers the question: headline, accuracy, health, then trajectory and errors; the summary is
  // a collapsed appendix at the end.
  ASSERT_GE(r->sections.size(), 4u);
  EXPECT_EQ(r->sections[0], "Accuracy against the reference");
  EXPECT_EQ(r->sections[1], "Health");
  EXPECT_EQ(r->sections[2], "Trajectory and errors against the reference");
  EXPECT_EQ(r->sections.back(), "Appendix: the full run summary");
  EXPECT_THAT(html, HasSubstr("Smoothed horizontal RMS 0.14 m (max 0.20 m); forward horizontal RMS 0.35 m (max 0.50 m). "
                              "Filter healthy, 1 re-initialization."));
  EXPECT_LT(html.find("id=\"headline\""), html.find("<h2>Accuracy against the reference</h2>"));
  // The run's fit warnings (summary.json `warnings`, docs/fusion.md §15) right under the headline.
  EXPECT_THAT(html, HasSubstr("<li>gyro bias estimate 958.0 °/h is beyond 3 σ of the spec (144.2 °/h): try imu.spec: "
                              "auto</li>"));
  EXPECT_LT(html.find("id=\"headline\""), html.find("id=\"fit-warnings\""));
  EXPECT_LT(html.find("id=\"fit-warnings\""), html.find("<h2>Accuracy against the reference</h2>"));
  EXPECT_LT(html.find("<h2>Health</h2>"), html.find("data:image/svg+xml"));
  EXPECT_THAT(html, HasSubstr("<th>GNSS code rejected by fault detection</th><td>7 of 1800 (0.4 %), 1 of them as "
                              "persistent faults</td>"));
  EXPECT_THAT(html, HasSubstr("<th>GNSS epochs skipped</th><td>2 without base, 0 outside the IMU span of 300 read</td>"));
  EXPECT_THAT(html, HasSubstr("<th>IMU samples rejected / skipped</th><td>4 / 6 of 30000</td>"));
  EXPECT_THAT(html, HasSubstr("<th>stance updates</th><td>150 ZUPT updates, 140 ZARU; 3 stances shorter than a mechanization "
                               "interval closed their own</td>"));
  EXPECT_THAT(html, HasSubstr("re-initialized at 225120.0 s: speed 12.3 m/s"));
  EXPECT_THAT(html, HasSubstr("Report warnings: none."));
  EXPECT_LT(html.find("<h2>Per-segment statistics"), html.find("<details id=\"appendix\">"));
  // Rounded to meaningful digits, integers as integers (outside the base64 of the plots).
  EXPECT_THAT(html, HasSubstr("<th>initial_yaw_deg</th><td>92.87</td>"));
  EXPECT_THAT(html, HasSubstr("<th>initial_gyro_bias_deg_per_h</th><td>[2424.9, 271.8, -1.23e-05]</td>"));
  EXPECT_THAT(html, HasSubstr("<th>output_epochs</th><td>300</td>"));
  EXPECT_THAT(html, HasSubstr("<th>health.healthy</th><td>yes</td>"));
  std::string text = html;
  for (size_t p = text.find("base64,"); p != std::string::npos; p = text.find("base64,", p + 1)) {
    const size_t end = text.find('"', p);
    text.erase(p + 7, end - p - 7);
  }
  // No digit, '.', then 5 or more digits (std::regex draws a false -Wmaybe-uninitialized from GCC 12 under ASan).
  size_t unrounded = std::string::npos;
  for (size_t p = text.find('.'); p != std::string::npos && unrounded == std::string::npos; p = text.find('.', p + 1)) {
    size_t d = p + 1;
    while (d < text.size() && std::isdigit(static_cast<unsigned char>(text[d]))) ++d;
    if (p > 0 && std::isdigit(static_cast<unsigned char>(text[p - 1])) && d - p - 1 >= 5) unrounded = p;
  }
  EXPECT_EQ(unrounded, std::string::npos) << "an unrounded number in report.html: " << text.substr(unrounded >= 10 ? unrounded - 10 : 0, 30);
  // The outage window table: window numbers as integers, TOW with one decimal.
  EXPECT_THAT(html, HasSubstr("<tr><td>1</td><td>225100.0</td><td>3.0</td><td>1.20</td>"));
  EXPECT_THAT(html, Not(HasSubstr("src=\"http")));  // nothing fetched from the network
  EXPECT_THAT(html, Not(HasSubstr("src=\"file")));
}

// With carrier phase (issue 48 item 7): solution.csv's solution_status over time and along the track, the share of
// each status and the time to the first fix; runs without the column (the test above) have no such section.
TEST(Report, CarrierStatusOverTimeAndAlongTheTrack) {
  const std::string d = test::temp_dir("report_carrier");
  test::write_report_fixture(d);
  {
    std::ifstream in(d + "/solution.csv");
    std::string out, line;
    std::getline(in, line);
    out += line + ",solution_status,n_fixed_ambiguities,ar_ratio\n";
    for (int i = 0; std::getline(in, line); ++i) {
      // 50 code, 10 float, 140 fixed (6 ambiguities), 20 ins, 80 float epochs
      const char* st = i < 50 ? "code" : i < 60 ? "float" : i < 200 ? "fixed" : i < 220 ? "ins" : "float";
      out += line + fmt::format(",{},{},{:.2f}\n", st, i >= 60 && i < 200 ? 6 : 0, i >= 60 && i < 200 ? 4.5 : 0.0);
    }
    std::ofstream(d + "/solution.csv") << out;
  }
  auto r = run_report_command(d);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  for (const auto& w : r->warnings) ADD_FAILURE() << "warning: " << w;
  EXPECT_EQ(r->plots, test::kReportFixturePlots + 3);  // status over time, track by status, fixed ambiguities
  EXPECT_NE(std::find(r->sections.begin(), r->sections.end(), "Carrier-phase solution status"), r->sections.end());
  const std::string html = test::read_text(d + "/report.html");
  EXPECT_THAT(html, HasSubstr("300 epochs of solution.csv carry a status"));
  EXPECT_THAT(html, HasSubstr("<tr><td>fixed</td><td>140</td><td>46.7 %</td><td>60.0</td></tr>"));
  EXPECT_THAT(html, HasSubstr("<tr><td>float</td><td>90</td><td>30.0 %</td><td>50.0</td></tr>"));
  EXPECT_THAT(html, HasSubstr("<tr><td>code</td><td>50</td><td>16.7 %</td><td>0.0</td></tr>"));
  EXPECT_THAT(html, HasSubstr("<tr><td>ins</td><td>20</td><td>6.7 %</td><td>200.0</td></tr>"));
  EXPECT_THAT(html, HasSubstr("alt=\"Track by solution status\""));
}

}  // namespace
}  // namespace pednav::io
