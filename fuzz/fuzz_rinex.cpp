// SPDX-License-Identifier: BSD-2-Clause
// libFuzzer target: RINEX observation and navigation files through pednav's RTKLIB adapter (gnss/rtklib/rinex).
// Input: byte 0 selects obs (even) or nav (odd), the rest is the file content. In the fuzz build RTKLIB's RINEX
// parser is compiled from Debian's source with the same instrumentation (fuzz/CMakeLists.txt), so memory errors
// inside it are found too. Any input must give data or an error naming the file, never a crash or a hang.
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "fuzz/fuzz_input.hpp"
#include "gnss/rtklib/rinex.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  pednav::fuzz::MemFile file(data + 1, size - 1);
  if (!file.ok()) return 0;
  if (data[0] % 2 == 0) {
    const pednav::gnss::SystemSelection all{true, true, true, true, true};
    auto obs = pednav::gnss::read_rinex_obs(file.path(), all);
    if (!obs) {
      if (obs.error().message.find(file.path()) == std::string::npos) std::abort();
      return 0;
    }
    for (size_t i = 0; i < obs->epochs.size(); ++i) {
      if (i > 0 && !(obs->epochs[i - 1].time < obs->epochs[i].time)) std::abort();  // one epoch per time, sorted
      for (const auto& s : obs->epochs[i].sats) {
        if (!std::isfinite(s.wavelength_m) || s.wavelength_m <= 0.0) std::abort();
      }
    }
  } else {
    auto nav = pednav::gnss::read_rinex_nav({file.path()});
    if (!nav && nav.error().message.find(file.path()) == std::string::npos) std::abort();
  }
  return 0;
}
