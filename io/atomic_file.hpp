// SPDX-License-Identifier: BSD-2-Clause
// Outputs are written to a temporary name in the target folder and renamed when complete, so a file with the
// final name is never half-written (a crash or a kill leaves only "<name>.tmp.<pid>").
#pragma once

#include <fstream>
#include <string>

#include "core/expected.hpp"

namespace pednav::io {

/// A file being written; commit() renames it to its final name, destruction without commit() removes it.
class AtomicFile {
 public:
  explicit AtomicFile(std::string final_path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// The stream to write to (check ok() before use).
  std::ofstream& stream() { return out_; }
  bool ok() const { return static_cast<bool>(out_); }
  /// Flush, close and rename to the final path.
  Expected<void> commit();
  const std::string& final_path() const { return final_path_; }

 private:
  std::string final_path_;
  std::string temp_path_;
  std::ofstream out_;
  bool committed_ = false;
};

/// Write `content` atomically to `path`.
Expected<void> write_file_atomic(const std::string& path, const std::string& content);

}  // namespace pednav::io
