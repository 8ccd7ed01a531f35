// SPDX-License-Identifier: BSD-2-Clause
// The reference tables of docs/cli.md and docs/configuration.md as data: for each table row, the `code` spans of
// its first cell and the "## " section it is in. Used by the tests that keep those pages equal to the executable's
// --help and to the configuration readers.
#pragma once

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace pednav::test {

struct DocRow {
  int line = 0;                    ///< 1-based line in the file
  std::string section;             ///< text of the last "## " heading above the row ("" before the first)
  std::vector<std::string> codes;  ///< the `code` spans of the first cell, in order
};

/// Table rows of a Markdown text whose first cell holds at least one `code` span ("\|" does not end a cell).
inline std::vector<DocRow> doc_table_rows(const std::string& markdown) {
  std::vector<DocRow> rows;
  std::istringstream in(markdown);
  std::string line, section;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.rfind("## ", 0) == 0) {
      section = line.substr(3);
      continue;
    }
    if (line.rfind("| ", 0) != 0) continue;
    std::string cell;
    for (size_t i = 1; i < line.size(); ++i) {
      if (line[i] == '\\' && i + 1 < line.size() && line[i + 1] == '|') {
        cell += '|';
        ++i;
      } else if (line[i] == '|') {
        break;
      } else {
        cell += line[i];
      }
    }
    DocRow r{n, section, {}};
    for (size_t b = cell.find('`'); b != std::string::npos; b = cell.find('`', b + 1)) {
      const size_t e = cell.find('`', b + 1);
      if (e == std::string::npos) break;
      r.codes.push_back(cell.substr(b + 1, e - b - 1));
      b = e;
    }
    if (!r.codes.empty()) rows.push_back(std::move(r));
  }
  return rows;
}

/// The whole text of a file ("" when it cannot be read).
inline std::string doc_text(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace pednav::test
