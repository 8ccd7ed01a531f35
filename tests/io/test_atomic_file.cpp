// SPDX-License-Identifier: BSD-2-Clause
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "io/atomic_file.hpp"
#include "tests/support/temp_dir.hpp"

namespace pednav::io {
namespace {

std::filesystem::path temp_dir() {
  static const std::filesystem::path d = test::temp_dir("atomic_file");
  return d;
}

TEST(AtomicFile, NothingWithTheFinalNameUntilCommit) {
  const auto dir = temp_dir();
  const std::string path = (dir / "out.csv").string();
  std::filesystem::remove(path);
  {
    AtomicFile f(path);
    ASSERT_TRUE(f.ok());
    f.stream() << "a,b\n";
    EXPECT_FALSE(std::filesystem::exists(path));
    ASSERT_TRUE(f.commit());
  }
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "a,b");
}

TEST(AtomicFile, AbandonedWriteLeavesNoFile) {
  const auto dir = temp_dir();
  const std::string path = (dir / "abandoned.csv").string();
  std::filesystem::remove(path);
  {
    AtomicFile f(path);
    f.stream() << "partial";
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(e.path().filename().string().find("abandoned.csv.tmp"), std::string::npos);
  }
}

TEST(AtomicFile, UnwritableFolderIsAnError) {
  auto r = write_file_atomic("/nonexistent_dir_pednav/x.json", "{}");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("/nonexistent_dir_pednav/x.json"), std::string::npos);
}

}  // namespace
}  // namespace pednav::io
