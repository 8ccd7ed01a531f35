// SPDX-License-Identifier: BSD-2-Clause
#include "io/log.hpp"

#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdio>
#include <vector>

namespace pednav::io {
namespace {
bool g_progress_enabled = true;
}

void set_progress_enabled(bool enabled) { g_progress_enabled = enabled; }
bool progress_enabled() { return g_progress_enabled; }

Expected<void> setup_logging(Verbosity verbosity, const std::string& log_file) {
  std::vector<spdlog::sink_ptr> sinks;
  auto console = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  console->set_level(verbosity == Verbosity::kQuiet     ? spdlog::level::err
                     : verbosity == Verbosity::kVerbose ? spdlog::level::debug
                                                        : spdlog::level::info);
  console->set_pattern("%^%l%$: %v");
  sinks.push_back(console);
  if (!log_file.empty()) {
    try {
      auto file = std::make_shared<spdlog::sinks::basic_file_sink_mt>(log_file, true);
      file->set_level(spdlog::level::trace);
      file->set_pattern("%Y-%m-%d %H:%M:%S.%e %l: %v");
      sinks.push_back(file);
    } catch (const spdlog::spdlog_ex& e) {
      return make_error(log_file + ": cannot open log file: " + e.what());
    }
  }
  auto logger = std::make_shared<spdlog::logger>("pednav", sinks.begin(), sinks.end());
  logger->set_level(spdlog::level::trace);
  spdlog::set_default_logger(logger);
  set_progress_enabled(verbosity != Verbosity::kQuiet);
  return {};
}

Progress::Progress(std::string label, int64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total > 0 ? total : 1),
      enabled_(enabled && g_progress_enabled),
      tty_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(int64_t done) {
  if (!enabled_ || finished_) return;
  const auto now = std::chrono::steady_clock::now();
  if (!shown_ && now - start_ < std::chrono::seconds(2)) return;
  shown_ = true;
  const double frac = std::min(1.0, static_cast<double>(done) / static_cast<double>(total_));
  if (tty_) {
    if (now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    const int width = 30;
    const int filled = static_cast<int>(frac * width);
    std::fprintf(stderr, "\r%s [%s%s] %3d%%", label_.c_str(), std::string(filled, '#').c_str(),
                 std::string(width - filled, ' ').c_str(), static_cast<int>(frac * 100.0));
    std::fflush(stderr);
  } else {
    const int decile = static_cast<int>(frac * 4.0);  // 25 % steps
    if (decile != last_decile_) {
      last_decile_ = decile;
      std::fprintf(stderr, "%s: %d%%\n", label_.c_str(), decile * 25);
    }
  }
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (enabled_ && shown_ && tty_) std::fprintf(stderr, "\r%s done%*s\n", label_.c_str(), 30, "");
}

}  // namespace pednav::io
