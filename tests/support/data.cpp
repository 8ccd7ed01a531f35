// SPDX-License-Identifier: BSD-2-Clause
#include "tests/support/data.hpp"

#include <cstdlib>
#include <filesystem>

namespace pednav::test {

std::string shared_data(const std::string& relative) {
  const char* override_dir = std::getenv("PEDNAV_SHARED_DATASETS");
  const std::filesystem::path base =
      override_dir ? std::filesystem::path(override_dir)
                   : std::filesystem::path(PEDNAV_SOURCE_DIR) / ".." / "shared" / "datasets";
  return (base / relative).lexically_normal().string();
}

std::string source_path(const std::string& relative) {
  return (std::filesystem::path(PEDNAV_SOURCE_DIR) / relative).lexically_normal().string();
}

bool in_ci() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

}  // namespace pednav::test
