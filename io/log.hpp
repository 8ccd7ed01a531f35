// SPDX-License-Identifier: BSD-2-Clause
// Logging setup (spdlog) and a progress display on stderr. Only io/ and apps/ log.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "core/expected.hpp"

namespace pednav::io {

enum class Verbosity { kQuiet, kNormal, kVerbose };

/// Configure the default logger: stderr at the given verbosity, plus an optional log file (everything).
Expected<void> setup_logging(Verbosity verbosity, const std::string& log_file);

/// Progress of long work on stderr: a redrawn bar on a terminal, a few percentage lines otherwise.
/// Silent when quiet or when the work finishes within ~2 s.
class Progress {
 public:
  Progress(std::string label, int64_t total, bool enabled = true);
  ~Progress();
  void update(int64_t done);
  void finish();

 private:
  std::string label_;
  int64_t total_;
  bool enabled_;
  bool tty_;
  bool shown_ = false;
  bool finished_ = false;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

/// Whether progress displays are allowed (false under --quiet).
void set_progress_enabled(bool enabled);
bool progress_enabled();

}  // namespace pednav::io
