// SPDX-License-Identifier: BSD-2-Clause
// Helpers of the libFuzzer targets: the first input byte selects a variant, the rest is the file content;
// readers that take a path get it through an anonymous in-memory file (memfd, /proc/self/fd/N).
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace pednav::fuzz {

/// An in-memory regular file holding `size` bytes at `data`; path() opens like a file on disk.
class MemFile {
 public:
  /// data, size: the file content (any bytes).
  MemFile(const uint8_t* data, size_t size) : fd_(::memfd_create("pednav_fuzz", 0)) {
    size_t done = 0;
    while (fd_ >= 0 && done < size) {
      const ssize_t w = ::write(fd_, data + done, size - done);
      if (w <= 0) break;
      done += static_cast<size_t>(w);
    }
  }
  ~MemFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  MemFile(const MemFile&) = delete;
  MemFile& operator=(const MemFile&) = delete;
  bool ok() const { return fd_ >= 0; }
  /// A path that opens this file (fopen, std::ifstream, stat).
  std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_;
};

}  // namespace pednav::fuzz
