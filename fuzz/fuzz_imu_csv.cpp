// SPDX-License-Identifier: BSD-2-Clause
// libFuzzer target: IMU CSV reader (io/imu_csv) with each built-in preset and two inline column maps.
// Input: byte 0 selects the format, the rest is the CSV text. Any input must give a log or an error, never a
// crash, a hang or a non-finite sample.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "io/config.hpp"
#include "io/imu_csv.hpp"

namespace {

std::vector<pednav::io::ImuFormat> formats() {
  std::vector<pednav::io::ImuFormat> v;
  for (const auto& name : pednav::io::imu_format_preset_names()) {
    auto f = pednav::io::imu_format_preset(name);
    if (!f) std::abort();  // a built-in preset must parse
    v.push_back(*f);
  }
  pednav::io::ImuFormat index;  // index time base, increments, full-scale checks, semicolons
  index.name = "inline_index";
  index.delimiter = ';';
  index.header_lines = 0;
  index.time_base = "index";
  index.index_rate_hz = 100.0;
  index.gyro_columns = {0, 1, 2};
  index.accel_columns = {3, 4, 5};
  index.gyro_unit = "deg";
  index.accel_unit = "mps";
  index.gyro_full_scale = 35.0;
  index.accel_full_scale = 160.0;
  v.push_back(index);
  pednav::io::ImuFormat sow;  // GPS seconds of week in ms, sign flips
  sow.name = "inline_gps_sow";
  sow.time_base = "gps_sow";
  sow.gps_week = 2300;
  sow.time_scale_s = 1e-3;
  sow.gyro_signs = Eigen::Vector3d(1, -1, -1);
  v.push_back(sow);
  return v;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::vector<pednav::io::ImuFormat> kFormats = formats();
  if (size < 1) return 0;
  const auto& fmt = kFormats[data[0] % kFormats.size()];
  auto log = pednav::io::parse_imu_csv(reinterpret_cast<const char*>(data + 1), size - 1, "fuzz.csv", fmt);
  if (!log) return 0;
  if (log->samples.size() < 2) std::abort();  // the reader promises at least 2 samples
  for (size_t i = 0; i < log->samples.size(); ++i) {
    const auto& s = log->samples[i];
    if (!s.omega_ib_b.allFinite() || !s.f_ib_b.allFinite()) std::abort();
    if (i > 0 && !(log->samples[i - 1].t < s.t)) std::abort();  // strictly increasing time
  }
  return 0;
}
