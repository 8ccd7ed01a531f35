// SPDX-License-Identifier: BSD-2-Clause
// report.html rendered by a real browser (Debian chromium, headless, no network): after loading, the page's own
// script counts the embedded plots the browser decoded (complete, naturalWidth > 0) into #plot-status; the dumped
// DOM must say all of them. Label `browser` (docs/outage.md: chromium's install time and the CI choice).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "io/report.hpp"
#include "tests/io/report_fixture.hpp"
#include "tests/sim/fixtures.hpp"
#include "tests/support/data.hpp"

namespace pednav {
namespace {

using ::testing::HasSubstr;

std::string chromium_path() {
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"}) {
    if (std::filesystem::exists(p)) return p;
  }
  return "";
}

std::string run_capture(const std::string& cmd) {
  std::string out;
  FILE* f = popen(cmd.c_str(), "r");
  if (!f) return out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) out.append(buf, n);
  pclose(f);
  return out;
}

TEST(BrowserReport, ChromiumShowsEveryPlot) {
  const std::string chromium = chromium_path();
  if (chromium.empty()) {
    if (test::in_ci()) FAIL() << "chromium missing under CI (scripts/setup installs it)";
    GTEST_SKIP() << "chromium not installed (Debian package chromium)";
  }
  const std::string d = test::temp_dir("browser_report");
  test::write_report_fixture(d);
  auto r = io::run_report_command(d);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  ASSERT_EQ(r->plots, test::kReportFixturePlots);
  const std::string profile = test::temp_dir("browser_profile");  // new empty user-data dir
  std::filesystem::remove_all(profile);
  std::filesystem::create_directories(profile);
  const std::string flags =
      " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking"
      " --disable-component-update --disable-sync --user-data-dir=" + profile;
  const std::string dom =
      run_capture(chromium + flags + " --virtual-time-budget=10000 --dump-dom file://" + r->path + " 2>/dev/null");
  EXPECT_THAT(dom, HasSubstr("plots shown: " + std::to_string(test::kReportFixturePlots) + " of " +
                             std::to_string(test::kReportFixturePlots)))
      << "the page's load script did not see every plot decoded; DOM starts: " << dom.substr(0, 400);
  // At 1280 px wide (a laptop screen) nothing runs past the right edge, with the appendix opened: the page's
  // script measures every element's right edge after layout.
  const std::string dom1280 = run_capture(chromium + flags + " --window-size=1280,900 --virtual-time-budget=10000 "
                                          "--dump-dom file://" + r->path + " 2>/dev/null");
  EXPECT_THAT(dom1280, ::testing::ContainsRegex("layout: fits 12[0-9][0-9] px"))
      << "layout status: " << dom1280.substr(dom1280.find("layout-status"), 120);
  // The first screen's text is what the browser shows first.
  EXPECT_LT(dom1280.find("Smoothed horizontal RMS 0.14 m"), dom1280.find("<h2>Health</h2>"));
  EXPECT_LT(dom1280.find("<h2>Health</h2>"), dom1280.find("Trajectory and errors against the reference"));
  // And a screenshot is a real, non-trivial PNG.
  const std::string png = d + "/report.png";
  run_capture(chromium + flags + " --window-size=1280,3000 --screenshot=" + png + " file://" + r->path +
              " >/dev/null 2>&1");
  ASSERT_TRUE(std::filesystem::exists(png));
  EXPECT_GT(std::filesystem::file_size(png), 20000u) << "screenshot suspiciously small (blank page?)";
  std::filesystem::remove_all(profile);
}

}  // namespace
}  // namespace pednav
