// SPDX-License-Identifier: BSD-2-Clause
// Temporary folders of one test process: unique to it (ctest runs tests as parallel processes, and two of them may
// use the same name), removed when it exits.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace pednav::test {

/// The temporary folders of this test process, removed when it exits (a test run would otherwise leave ~0.9 GB in
/// the temporary directory); PEDNAV_KEEP_TEST_DIRS=1 keeps them to look at a failure.
class TempDirRegistry {
 public:
  void add(const std::filesystem::path& p) { dirs_.push_back(p); }
  ~TempDirRegistry() {
    const char* keep = std::getenv("PEDNAV_KEEP_TEST_DIRS");
    if (keep && std::string(keep) == "1") return;
    std::error_code ec;
    for (const auto& d : dirs_) std::filesystem::remove_all(d, ec);
  }

 private:
  std::vector<std::filesystem::path> dirs_;
};

inline TempDirRegistry& temp_dir_registry() {
  static TempDirRegistry registry;
  return registry;
}

/// The path of this process's temporary folder `name` (pednav_test_<name>_<pid>), registered for removal at exit;
/// not created.
inline std::filesystem::path temp_dir_path(const std::string& name) {
  const auto p = std::filesystem::temp_directory_path() / ("pednav_test_" + name + "_" + std::to_string(::getpid()));
  temp_dir_registry().add(p);
  return p;
}

/// A fresh empty temporary folder of this process, removed when the test process exits.
inline std::string temp_dir(const std::string& name) {
  const auto p = temp_dir_path(name);
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p.string();
}

}  // namespace pednav::test
