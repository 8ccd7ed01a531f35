// SPDX-License-Identifier: BSD-2-Clause
// libFuzzer target: reference trajectory readers (io/trajectory_io): NMEA GGA, RTKLIB .pos, CSV, auto-detection.
// Input: byte 0 selects the reader, the rest is the file content. Any input must give a trajectory or an error
// naming the file, never a crash or a hang; an accepted trajectory has finite points in strictly increasing time.
#include <cstdint>
#include <cstdlib>

#include "fuzz/fuzz_input.hpp"
#include "io/trajectory_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  pednav::fuzz::MemFile file(data + 1, size - 1);
  if (!file.ok()) return 0;
  pednav::io::TrajectoryReadOptions opt;
  switch (data[0] % 5) {
    case 0: opt.format = pednav::io::TrajectoryFormat::kNmea; break;
    case 1: opt.format = pednav::io::TrajectoryFormat::kNmea; opt.nmea_date = "2019-03-05"; opt.nmea_qualities = {4, 5}; break;
    case 2: opt.format = pednav::io::TrajectoryFormat::kPos; break;
    case 3: opt.format = pednav::io::TrajectoryFormat::kCsv; break;
    default: opt.format = pednav::io::TrajectoryFormat::kAuto; break;
  }
  auto r = pednav::io::read_trajectory(file.path(), opt);
  if (!r) {
    if (r.error().message.find(file.path()) == std::string::npos && r.error().message.find("nmea date") == std::string::npos)
      std::abort();  // every reader error names the file
    return 0;
  }
  const auto& pts = r->trajectory.points;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!pts[i].p.allFinite()) std::abort();
    if (i > 0 && !(pts[i - 1].t < pts[i].t)) std::abort();
  }
  return 0;
}
