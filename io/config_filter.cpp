// YAML section reader: filter options (mechanization rate, ZUPT, fault rejection, smoother).
#include "io/config.hpp"
#include "io/yaml_schema.hpp"

namespace pednav::io {

void read_filter_section(YamlMap& top, RunConfig& out) {
  top.number("mechanization_rate_hz", out.mechanization_rate_hz, false, 1e-3, 2000.0);
  {
    YamlMap z = top.map("zupt");
    z.choice("detector", out.zupt.detector, {"mv", "shoe", "hmm"});
    z.choice("form", out.zupt.form, {"D", "F"});
  }
  {
    YamlMap f = top.map("fault_rejection");
    f.number("probability", out.fault_rejection_probability, false, 0.5, 1.0 - 1e-12);
  }
  {
    YamlMap s = top.map("smoother");
    s.boolean("enabled", out.smoother_enabled);
  }
}

}  // namespace pednav::io
