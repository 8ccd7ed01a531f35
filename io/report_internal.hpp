// SPDX-License-Identifier: BSD-2-Clause
// The parts of report.html (io/report.hpp) shared by its files: io/report_common.cpp (reading a run folder's
// files, number formatting, CSV tables), io/report_sections.cpp (headline, accuracy, health, appendix and outage
// sections), io/report.cpp (the page). Internal to io/ (installed with the other headers, not an interface).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "core/time.hpp"
#include "eval/trajectory.hpp"
#include "io/plot.hpp"
#include "io/report.hpp"

namespace pednav::io::report_detail {
namespace fs = std::filesystem;

/// The cells of one CSV line (a trailing comma gives an empty last cell).
std::vector<std::string> split(const std::string& line);
/// s without trailing CR/spaces and leading spaces.
std::string trim(std::string s);
/// The whole file ("" when it cannot be read).
std::string read_text(const fs::path& p);
/// s with <, >, &, " escaped for HTML.
std::string esc(const std::string& s);
/// j[key] formatted with f, or "–" when it is not a number.
std::string num(const nlohmann::json& j, const char* key, const char* f = "{:.2f}");

/// A solution file as time + ECEF + optional sigma/satellite/ZUPT columns.
struct Solution {
  std::string name;
  std::vector<GpsTime> t;
  std::vector<Eigen::Vector3d> p_e;
  CsvTable table;
};
/// solution.csv / smoothed.csv / gnss.csv (ECEF or geodetic columns); errors name the file.
Expected<Solution> load_solution(const fs::path& path, const std::string& name);
/// The solution's positions as a trajectory (GPST, ECEF).
eval::Trajectory trajectory_of(const Solution& s);
/// The reference named by config.resolved.yaml (path as written, else relative to the run folder); ref_name gets
/// the path read. Problems go to warnings.
std::optional<eval::Trajectory> load_reference(const fs::path& dir, std::vector<std::string>& warnings,
                                               std::string& ref_name);

/// The page being built: sections, paragraphs, plots (SVG data URIs) and tables.
class Html {
 public:
  std::string body;
  int plots = 0;
  std::vector<std::string> sections;
  std::vector<std::string>& warnings;
  explicit Html(std::vector<std::string>& w) : warnings(w) {}
  void section(const std::string& title) {
    sections.push_back(title);
    body += "<h2>" + esc(title) + "</h2>\n";
  }
  void para(const std::string& text) { body += "<p>" + esc(text) + "</p>\n"; }
  void row_open() { body += "<div class=\"row\">\n"; }  // plots side by side while the page is wide enough
  void row_close() { body += "</div>\n"; }
  void plot(const PlotSpec& spec, const std::string& caption) {
    auto svg = render_svg(spec);
    if (!svg) {
      warnings.push_back(svg.error().message);
      body += "<p class=\"warn\">plot not rendered: " + esc(svg.error().message) + "</p>\n";
      return;
    }
    ++plots;
    body += "<figure><img class=\"plot\" alt=\"" + esc(spec.title) + "\" src=\"data:image/svg+xml;base64," +
            base64(*svg) + "\"><figcaption>" + esc(caption) + "</figcaption></figure>\n";
  }
  void table(const std::vector<std::string>& head, const std::vector<std::vector<std::string>>& rows) {
    body += "<table><thead><tr>";
    for (const auto& h : head) body += "<th>" + esc(h) + "</th>";
    body += "</tr></thead><tbody>\n";
    for (const auto& r : rows) {
      body += "<tr>";
      for (const auto& c : r) body += "<td>" + esc(c) + "</td>";
      body += "</tr>\n";
    }
    body += "</tbody></table>\n";
  }
};

/// A number with the digits that mean something: integers as integers, otherwise three significant digits.
std::string pretty_number(double x);
/// A JSON value for a person: rounded numbers, lists without quotes, at most 12 items shown.
std::string pretty(const nlohmann::json& v);
/// summary.json of a run (not of an outage study), or null.
nlohmann::json run_summary(const fs::path& dir, std::vector<std::string>& warnings);
/// The value at a dotted path ("gnss.code.used") or null.
const nlohmann::json* at_path(const nlohmann::json& j, const std::string& path);
/// The number at a dotted path, or -1.
long long count_at(const nlohmann::json& j, const std::string& path);
/// The sum of the counts of a {reason: count} object (accounting's rejected/skipped), or -1.
long long sum_counts(const nlohmann::json& j, const std::string& path);
/// "n of N (x %)", or "n" without a total.
std::string share(long long n, long long of);

/// One sentence at the top: the accuracy of each solution against the reference and the filter's health.
std::string headline(const fs::path& dir, const nlohmann::json& summary);
/// The run's fit warnings (summary.json `warnings`) as a list under the headline; "" without any.
std::string fit_warnings_html(const nlohmann::json& summary);
/// Accuracy against the reference: seed 004's bins (Tables 1-2), then the statistics, one row per solution.
void evaluation_section(Html& h, const fs::path& dir);
/// Health of the run: what was rejected, re-initialized, skipped; then the report's own warnings.
std::string health_html(const nlohmann::json& j, const std::vector<std::string>& warnings);
/// Every key of summary.json, flattened to dotted names, values rounded; collapsed at the end of the page.
std::string appendix_html(const nlohmann::json& j);
/// The carrier-phase status section (io/report_carrier.cpp) when `csv` (solution.csv or gnss.csv) has a
/// solution_status column:
/// status over time and along the track (East/North about p0_e), shares, time to first fix. False: no section.
bool carrier_status_section(Html& h, const fs::path& csv, GpsTime t0, const Eigen::Vector3d& p0_e);
/// An outage study found in d (the run folder or one of its subfolders).
void outage_section(Html& h, const fs::path& d, const fs::path& run_dir);

}  // namespace pednav::io::report_detail
