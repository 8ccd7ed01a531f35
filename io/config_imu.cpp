// YAML section reader: `imu:` (log file, format, noise spec).
#include "io/config.hpp"
#include "io/yaml_schema.hpp"

namespace pednav::io {

void read_imu_section(YamlMap& top, ImuConfig& out) {
  if (!top.has("imu")) return;
  YamlMap imu = top.map("imu");
  imu.path("file", out.file, true);
  imu.text("format", out.format_preset);
  imu.text("spec", out.spec_preset);
}

}  // namespace pednav::io
