// SPDX-License-Identifier: BSD-2-Clause
// `pednav report OUTDIR`: one self-contained report.html (tables + plots embedded as SVG data URIs, readable
// offline) of a run directory (pednav run / gnss outputs) and of any outage study found in it or its subfolders.
#pragma once

#include <string>
#include <vector>

#include "core/expected.hpp"

namespace pednav::io {

/// A CSV file with a header row, every column as numbers (empty or non-numeric cells are NaN).
struct CsvTable {
  std::vector<std::string> header;
  std::vector<std::vector<double>> columns;  ///< columns[k][row]
  size_t rows = 0;
  /// The column named `name`, or nullptr.
  const std::vector<double>* column(const std::string& name) const;
};

/// Read a numeric CSV table; errors name the file and line.
Expected<CsvTable> read_csv_table(const std::string& path);

/// Standard base64 (RFC 4648) of bytes, for data URIs.
std::string base64(const std::string& bytes);

/// What the report contains.
struct ReportResult {
  std::string path;                    ///< report.html written
  int plots = 0;                       ///< images embedded
  std::vector<std::string> sections;   ///< section titles, in order
  std::vector<std::string> warnings;   ///< parts left out and why
};

/// Build OUTDIR/report.html from the files of a run directory (solution.csv or gnss.csv, smoothed.csv,
/// summary.json, evaluation*.json, config.resolved.yaml for the reference, outage studies in OUTDIR or one level
/// below). Fails when the folder holds nothing to report.
Expected<ReportResult> run_report_command(const std::string& run_dir);

}  // namespace pednav::io
