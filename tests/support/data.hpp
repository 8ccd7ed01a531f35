// SPDX-License-Identifier: BSD-2-Clause
// Access to the real data sets in ../shared/datasets: skip when absent, FAIL under CI=true.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace pednav::test {

/// Absolute path of a file or folder under ../shared/datasets (relative to the project root).
std::string shared_data(const std::string& relative);
/// Absolute path inside the project source tree.
std::string source_path(const std::string& relative);
/// True when running under CI (env CI=true).
bool in_ci();

}  // namespace pednav::test

/// Use at the top of a data test: skips (or fails under CI=true) when the shared data file is missing.
#define PEDNAV_REQUIRE_DATA(path_expr)                                                        \
  do {                                                                                        \
    const std::string pednav_required_path_ = (path_expr);                                    \
    if (!std::filesystem::exists(pednav_required_path_)) {                                    \
      if (::pednav::test::in_ci()) FAIL() << "shared data missing under CI: " << pednav_required_path_; \
      GTEST_SKIP() << "shared data missing: " << pednav_required_path_;                      \
    }                                                                                         \
  } while (0)
