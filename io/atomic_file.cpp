// SPDX-License-Identifier: BSD-2-Clause
#include "io/atomic_file.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>

namespace pednav::io {

AtomicFile::AtomicFile(std::string final_path)
    : final_path_(std::move(final_path)),
      temp_path_(final_path_ + ".tmp." + std::to_string(::getpid())),
      out_(temp_path_, std::ios::out | std::ios::trunc | std::ios::binary) {}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(temp_path_, ec);
  }
}

Expected<void> AtomicFile::commit() {
  if (!out_) return make_error(final_path_ + ": cannot write (" + temp_path_ + ")");
  out_.flush();
  out_.close();
  if (out_.fail()) return make_error(final_path_ + ": write failed (disk full?)");
  if (std::rename(temp_path_.c_str(), final_path_.c_str()) != 0) {
    return make_error(final_path_ + ": cannot rename the temporary file into place");
  }
  committed_ = true;
  return {};
}

Expected<void> write_file_atomic(const std::string& path, const std::string& content) {
  AtomicFile f(path);
  if (!f.ok()) return make_error(path + ": cannot open for writing");
  f.stream() << content;
  return f.commit();
}

}  // namespace pednav::io
