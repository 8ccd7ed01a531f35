// SPDX-License-Identifier: BSD-2-Clause
// docs/cli.md cannot drift from the executable (issue 49 item 7): every subcommand of `pednav --help` has a section
// "## `pednav NAME`", every flag of `pednav NAME --help` is in the first column of that section's option table, and
// every flag in such a first column is one that `pednav NAME --help` lists; the same for the global options.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/data.hpp"
#include "tests/support/doc_tables.hpp"

namespace pednav {
namespace {

std::string pednav_output(const std::string& args) {
  const std::string cmd = std::string(PEDNAV_BINARY_DIR) + "/bin/pednav " + args + " 2>&1";
  std::string out;
  if (FILE* p = popen(cmd.c_str(), "r")) {
    char buf[4096];
    for (size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    pclose(p);
  }
  return out;
}

// The lines of one section of CLI11's help ("Options:", "Subcommands:") up to the next blank line.
std::vector<std::string> help_section(const std::string& help, const std::string& title) {
  std::vector<std::string> lines;
  std::istringstream in(help);
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside) {
      inside = line.rfind(title, 0) == 0;
      continue;
    }
    if (line.find_first_not_of(' ') == std::string::npos) break;
    lines.push_back(line);
  }
  return lines;
}

// The flags of a help text: the first word of each option line ("  -o,--out TEXT", "  --no-plot{false}").
std::set<std::string> help_flags(const std::string& help) {
  std::set<std::string> flags;
  for (const std::string& line : help_section(help, "Options:")) {
    if (line.rfind("  -", 0) != 0) continue;  // a continuation line of a long description
    std::string word = line.substr(2, line.find(' ', 2) - 2);
    word = word.substr(0, word.find('{'));
    std::istringstream parts(word);
    for (std::string f; std::getline(parts, f, ',');) flags.insert(f);
  }
  return flags;
}

std::set<std::string> help_subcommands(const std::string& help) {
  std::set<std::string> names;
  for (const std::string& line : help_section(help, "Subcommands:")) {
    if (line.rfind("  ", 0) == 0 && line.size() > 2 && line[2] != ' ') {
      names.insert(line.substr(2, line.find(' ', 2) - 2));
    }
  }
  return names;
}

// The flags in the first cells of docs/cli.md's tables, per section: "global" or the subcommand's name.
// "<prefix><name><suffix>" with name of [a-z-]+: the name, or "". (Hand-written matchers: GCC 12's std::regex
// trips -Wmaybe-uninitialized under ASan -O2.)
std::string command_name(const std::string& s, const std::string& prefix, const std::string& suffix) {
  if (s.size() <= prefix.size() + suffix.size() || s.compare(0, prefix.size(), prefix) != 0 ||
      s.compare(s.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return "";
  }
  const std::string name = s.substr(prefix.size(), s.size() - prefix.size() - suffix.size());
  for (const char c : name) {
    if (!((c >= 'a' && c <= 'z') || c == '-')) return "";
  }
  return name;
}

// -x or --name with [A-Za-z][A-Za-z0-9-]* after the dashes.
bool is_flag(const std::string& w) {
  const size_t dashes = w.compare(0, 2, "--") == 0 ? 2 : (w.compare(0, 1, "-") == 0 ? 1 : 0);
  if (dashes == 0 || w.size() == dashes || !std::isalpha(static_cast<unsigned char>(w[dashes]))) return false;
  for (size_t i = dashes; i < w.size(); ++i) {
    if (!(std::isalnum(static_cast<unsigned char>(w[i])) || w[i] == '-')) return false;
  }
  return true;
}

std::map<std::string, std::set<std::string>> documented_flags(const std::string& markdown) {
  std::map<std::string, std::set<std::string>> out;
  for (const auto& row : test::doc_table_rows(markdown)) {
    std::string where = command_name(row.section, "`pednav ", "`");
    if (where.empty() && row.section == "Global options") where = "global";
    if (where.empty()) continue;
    for (const std::string& code : row.codes) {
      std::string spaced = code;
      std::replace(spaced.begin(), spaced.end(), ',', ' ');
      std::istringstream words(spaced);
      for (std::string w; words >> w;) {
        if (is_flag(w)) out[where].insert(w);
      }
    }
  }
  return out;
}

std::set<std::string> documented_commands(const std::string& markdown) {
  std::set<std::string> names;
  std::istringstream in(markdown);
  for (std::string line; std::getline(in, line);) {
    const std::string name = command_name(line, "## `pednav ", "`");
    if (!name.empty()) names.insert(name);
  }
  return names;
}

class CliDocs : public ::testing::Test {
 protected:
  void SetUp() override {
    markdown_ = test::doc_text(test::source_path("docs/cli.md"));
    ASSERT_FALSE(markdown_.empty()) << "docs/cli.md missing";
    top_help_ = pednav_output("--help");
    ASSERT_NE(top_help_.find("Subcommands:"), std::string::npos) << "pednav --help:\n" << top_help_;
  }
  std::string markdown_, top_help_;
};

TEST_F(CliDocs, EverySubcommandHasItsSectionAndNoOther) {
  const std::set<std::string> in_help = help_subcommands(top_help_);
  const std::set<std::string> in_docs = documented_commands(markdown_);
  ASSERT_GE(in_help.size(), 14u) << top_help_;
  for (const auto& c : in_help) EXPECT_TRUE(in_docs.count(c)) << "docs/cli.md has no section ## `pednav " << c << "`";
  for (const auto& c : in_docs) {
    EXPECT_TRUE(in_help.count(c)) << "docs/cli.md documents `pednav " << c << "`, which pednav --help does not list";
  }
}

TEST_F(CliDocs, EveryFlagIsDocumentedAndEveryDocumentedFlagExists) {
  const auto docs = documented_flags(markdown_);
  auto check = [&](const std::string& where, const std::string& help) {
    const std::set<std::string> flags = help_flags(help);
    ASSERT_FALSE(flags.empty()) << where << ": no options in --help:\n" << help;
    const auto it = docs.find(where);
    const std::set<std::string> documented = it == docs.end() ? std::set<std::string>{} : it->second;
    for (const auto& f : flags) {
      if (where != "global" && (f == "-h" || f == "--help")) continue;  // every subcommand has it (Global options)
      EXPECT_TRUE(documented.count(f)) << "docs/cli.md, section " << where << ": flag " << f
                                       << " of --help is not in an option table";
    }
    for (const auto& f : documented) {
      EXPECT_TRUE(flags.count(f)) << "docs/cli.md, section " << where << ": documents " << f
                                  << ", which --help does not list";
    }
  };
  check("global", top_help_);
  for (const auto& c : help_subcommands(top_help_)) check(c, pednav_output(c + " --help"));
}

}  // namespace
}  // namespace pednav
