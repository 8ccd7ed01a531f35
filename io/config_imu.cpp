// SPDX-License-Identifier: BSD-2-Clause
// YAML section reader: `imu:` (log file, format = preset name or inline column map, spec = preset name or
// inline unit-suffixed values). Keys are documented in docs/configuration.md ("IMU log format", "IMU spec").
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "io/config.hpp"
#include "io/yaml_schema.hpp"

namespace pednav::io {
namespace {

constexpr double kG0 = 9.80665;

std::string joined_names(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& n : v) s += (s.empty() ? "" : ", ") + n;
  return s;
}

constexpr int kMaxColumn = 10000;  // 0-based column indices of the IMU CSV (also time.column, stance.column)

void read_columns(YamlMap& m, const char* key, std::array<int, 3>& out) {
  std::vector<int> v;
  if (!m.integers(key, v, 0, kMaxColumn) || v.empty()) return;  // a bad index is reported with the range
  if (v.size() != 3) {
    m.problem(key, "expected 3 column indices, got " + std::to_string(v.size()));
    return;
  }
  std::copy(v.begin(), v.end(), out.begin());
}

}  // namespace

void read_imu_format(YamlMap& m, ImuFormat& out) {
  std::string delim(1, out.delimiter);
  m.text("delimiter", delim);
  // (No `delim = "\t"`: GCC 12 reports a false -Wrestrict on that assignment once the function is inlined.)
  if (delim == "tab" || delim == "\\t") {
    out.delimiter = '\t';
  } else if (delim.size() != 1) {
    m.problem("delimiter", "expected one character (or 'tab'), got '" + delim + "'");
  } else {
    out.delimiter = delim[0];
  }
  m.integer("header_lines", out.header_lines, false, 0, 1000);
  {
    YamlMap t = m.map("time");
    t.choice("base", out.time_base, {"gps_sow", "gpst_unix", "relative", "index"});
    t.integer("column", out.time_column, false, 0, kMaxColumn);
    std::string unit = "s";
    t.choice("unit", unit, {"s", "ms", "us", "ns"});
    out.time_scale_s = unit == "s" ? 1.0 : unit == "ms" ? 1e-3 : unit == "us" ? 1e-6 : 1e-9;
    t.integer("gps_week", out.gps_week, false, 0, 10000);
    int start_week = -1;
    double start_tow = 0.0;
    t.integer("start_gps_week", start_week, false, 0, 10000);
    t.number("start_gps_tow_s", start_tow, false, 0.0, 604800.0);
    if (start_week >= 0) out.start_epoch = GpsTime::from_week_tow(start_week, start_tow);
    if (t.has("start_gps_tow_s") && start_week < 0) t.problem("start_gps_week", "required with start_gps_tow_s");
    t.number("rate_hz", out.index_rate_hz, false, 1e-3, 1e6);
    if (out.time_base == "gps_sow" && out.gps_week < 0) t.problem("gps_week", "required key is missing (base gps_sow)");
    if (out.time_base == "index" && !(out.index_rate_hz > 0)) t.problem("rate_hz", "required key is missing (base index)");
  }
  {
    YamlMap g = m.map("gyro");
    read_columns(g, "columns", out.gyro_columns);
    g.choice("unit", out.gyro_unit, {"rad_per_s", "deg_per_s", "rad", "deg"});
    g.vector3("signs", out.gyro_signs);
    double fs_deg = out.gyro_full_scale * kRadToDeg;
    g.number("full_scale_deg_per_s", fs_deg, false, 0.0, 1e5);
    out.gyro_full_scale = fs_deg * kDegToRad;
  }
  {
    YamlMap a = m.map("accel");
    read_columns(a, "columns", out.accel_columns);
    a.choice("unit", out.accel_unit, {"mps2", "g", "mps"});
    a.vector3("signs", out.accel_signs);
    double fs_g = out.accel_full_scale / kG0;
    a.number("full_scale_g", fs_g, false, 0.0, 1e4);
    out.accel_full_scale = fs_g * kG0;
  }
  if (m.has("stance")) {
    YamlMap st = m.map("stance");
    st.integer("column", out.stance_column, true, 0, kMaxColumn);
  }
  if (m.has("mag")) {
    YamlMap mg = m.map("mag");
    read_columns(mg, "columns", out.mag_columns);
    if (!mg.has("columns")) mg.problem("columns", "required key is missing");
    std::string unit = "ut";
    mg.choice("unit", unit, {"ut", "gauss", "nt", "mgauss"});
    out.mag_scale_to_ut = unit == "gauss" ? 100.0 : unit == "mgauss" ? 0.1 : unit == "nt" ? 1e-3 : 1.0;
    mg.vector3("signs", out.mag_signs);
    for (int i = 0; i < 3; ++i) {
      if (std::abs(out.mag_signs(i)) != 1.0) m.problem("mag", "signs must each be 1 or -1");
    }
  }
  for (int i = 0; i < 3; ++i) {
    if (std::abs(out.gyro_signs(i)) != 1.0) m.problem("gyro", "signs must each be 1 or -1");
    if (std::abs(out.accel_signs(i)) != 1.0) m.problem("accel", "signs must each be 1 or -1");
  }
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();
  if (m.has("mounting_rpy_deg")) {
    m.vector3("mounting_rpy_deg", rpy_deg);
    out.R_b_s = R_n_b_from_euler(rpy_deg.x() * kDegToRad, rpy_deg.y() * kDegToRad, rpy_deg.z() * kDegToRad);
    out.mounting_rpy_deg = rpy_deg;
  } else {
    m.raw("mounting_rpy_deg");
  }
  m.number("max_gap_s", out.max_gap_s, false, 1e-6, 3600.0);
  m.number("gap_factor", out.gap_factor, false, 1.01, 1000.0);
  m.number("rest_tolerance_mps2", out.rest_tolerance_mps2, false, 0.0, 100.0);
}

namespace {
// The spec keys of a run configuration: YAML key, field, YAML unit -> SI factor.
struct SpecKey {
  const char* key;
  double ins::ImuSpec::*field;
  double factor;
};
const std::vector<SpecKey>& spec_keys() {
  const double dps = kDegToRad, dph = kDegToRad / 3600.0, mg = 1e-3 * kG0;
  static const std::vector<SpecKey> keys{
      {"gyro_arw_deg_per_sqrt_hr", &ins::ImuSpec::gyro_arw, kDegToRad / 60.0},
      {"accel_vrw_mps_per_sqrt_hr", &ins::ImuSpec::accel_vrw, 1.0 / 60.0},
      {"gyro_bias_instability_deg_per_hr", &ins::ImuSpec::gyro_bias_instability, dph},
      {"gyro_bias_tau_s", &ins::ImuSpec::gyro_bias_tau_s, 1.0},
      {"gyro_bias_rw_deg_per_hr_per_sqrt_hr", &ins::ImuSpec::gyro_bias_rw, dph / 60.0},
      {"gyro_bias_initial_deg_per_s", &ins::ImuSpec::gyro_bias_initial, dps},
      {"accel_bias_instability_mg", &ins::ImuSpec::accel_bias_instability, mg},
      {"accel_bias_tau_s", &ins::ImuSpec::accel_bias_tau_s, 1.0},
      {"accel_bias_rw_mps2_per_sqrt_s", &ins::ImuSpec::accel_bias_rw, 1.0},
      {"accel_bias_initial_mg", &ins::ImuSpec::accel_bias_initial, mg},
      {"gyro_scale_ppm", &ins::ImuSpec::gyro_scale_sigma, 1e-6},
      {"accel_scale_ppm", &ins::ImuSpec::accel_scale_sigma, 1e-6},
      {"scale_tau_s", &ins::ImuSpec::scale_tau_s, 1.0},
      {"gyro_g_sensitivity_deg_per_s_per_g", &ins::ImuSpec::gyro_g_sensitivity, dps / kG0},
      {"gyro_range_deg_per_s", &ins::ImuSpec::gyro_range, dps},
      {"accel_range_g", &ins::ImuSpec::accel_range, kG0},
  };
  return keys;
}
}  // namespace

void read_imu_spec(YamlMap& m, ins::ImuSpec& s) {
  for (const SpecKey& k : spec_keys()) {
    double v = s.*k.field / k.factor;
    m.number(k.key, v, false, 0.0, 1e12);
    s.*k.field = v * k.factor;
  }
  if (s.gyro_bias_instability > 0 && !(s.gyro_bias_tau_s > 0))
    m.problem("gyro_bias_tau_s", "must be > 0 when gyro_bias_instability_deg_per_hr is given");
  if (s.accel_bias_instability > 0 && !(s.accel_bias_tau_s > 0))
    m.problem("accel_bias_tau_s", "must be > 0 when accel_bias_instability_mg is given");
}

Expected<ImuFormat> imu_format_preset(const std::string& name) {
  const std::string text = imu_format_preset_yaml(name);
  if (text.empty())
    return make_error("unknown IMU format preset '" + name + "' (expected one of " +
                      joined_names(imu_format_preset_names()) + ")");
  auto problems = std::make_shared<YamlProblems>();
  problems->file = "datasets/imu_formats/" + name + ".yaml";
  ImuFormat f;
  f.name = name;
  {
    YamlMap m(YAML::Load(text), "", problems, ".");
    read_imu_format(m, f);
  }
  if (!problems->empty()) return make_error(problems->joined());
  return f;
}

void read_imu_section(YamlMap& top, ImuConfig& out) {
  if (!top.has("imu")) return;
  YamlMap imu = top.map("imu");
  imu.path("file", out.file, true);
  if (imu.has("format")) {
    out.has_format = true;
    const YAML::Node n = imu.raw("format");
    if (n.IsScalar()) {
      imu.text("format", out.format_preset);
      auto f = imu_format_preset(out.format_preset);
      if (f) {
        out.format = *f;
      } else {
        imu.problem("format", f.error().message);
      }
    } else {
      YamlMap m = imu.map("format");
      out.format.name = "inline";
      read_imu_format(m, out.format);
    }
  }
  if (imu.has("spec")) {
    out.has_spec = true;
    if (imu.raw("spec").IsScalar() && imu.raw("spec").Scalar() == "auto") {
      out.spec_auto = true;  // resolved from the log at run time (pipeline/self_calibration)
      out.spec.name = "auto";
      std::string ignored;
      imu.text("spec", ignored);  // mark the key as read
    } else {
      read_imu_spec_entry(imu, "spec", out.spec, out.spec_preset);
    }
  } else if (imu.has("file")) {
    // No spec: the log calibrates itself (pipeline/self_calibration), as with `spec: auto` (docs/configuration.md).
    out.spec_auto = true;
    out.spec_defaulted = true;
    out.spec.name = "auto";
  }
}

void read_imu_spec_entry(YamlMap& m, const std::string& key, ins::ImuSpec& spec, std::string& preset) {
  auto start_from_preset = [&](YamlMap& where, const std::string& preset_key) {
    if (preset.empty()) return;
    if (auto s = ins::imu_spec_preset(preset)) {
      spec = *s;
    } else {
      where.problem(preset_key, s.error().message);
    }
  };
  if (m.has(key) && !m.raw(key).IsScalar()) {
    YamlMap sm = m.map(key);
    sm.text("preset", preset);
    start_from_preset(sm, "preset");
    spec.name = preset.empty() ? "inline" : preset + "+inline";
    read_imu_spec(sm, spec);
  } else {
    m.text(key, preset);
    start_from_preset(m, key);
  }
}

std::string imu_spec_flow_yaml(const ins::ImuSpec& spec, const std::string& preset) {
  const auto p = ins::imu_spec_preset(preset);  // an error for "" and unknown names: every key is written
  std::string y = p ? "preset: " + preset : std::string();
  for (const SpecKey& k : spec_keys()) {
    const double v = spec.*k.field;
    if (p && (*p).*k.field == v) continue;
    y += fmt::format("{}{}: {}", y.empty() ? "" : ", ", k.key, v / k.factor);  // shortest decimal that reads back
  }
  return "{" + y + "}";
}

void emit_imu_spec(YAML::Emitter& e, const ins::ImuSpec& spec, const std::string& preset) {
  if (!preset.empty()) {
    auto p = ins::imu_spec_preset(preset);
    bool same = p.has_value();
    for (const SpecKey& k : spec_keys()) same = same && (*p).*k.field == spec.*k.field;
    if (same) {
      e << preset;
      return;
    }
  }
  e << YAML::BeginMap;
  if (!preset.empty()) e << YAML::Key << "preset" << YAML::Value << preset;
  for (const SpecKey& k : spec_keys()) e << YAML::Key << k.key << YAML::Value << yaml_number(spec.*k.field / k.factor);
  e << YAML::EndMap;
}

void emit_imu_format(YAML::Emitter& e, const ImuFormat& f) {
  auto unit_of_scale = [](double scale, std::initializer_list<std::pair<double, const char*>> units) {
    for (const auto& [s, name] : units)
      if (scale == s) return name;
    return units.begin()->second;  // not reached: every scale the reader sets is listed
  };
  auto columns = [](const std::array<int, 3>& c) { return std::vector<int>(c.begin(), c.end()); };
  auto signs = [](const Eigen::Vector3d& v) { return yaml_numbers({v.x(), v.y(), v.z()}); };
  e << YAML::BeginMap;
  e << YAML::Key << "delimiter" << YAML::Value
    << (f.delimiter == '\t' ? std::string("tab") : std::string(1, f.delimiter));
  e << YAML::Key << "header_lines" << YAML::Value << f.header_lines;
  e << YAML::Key << "time" << YAML::Value << YAML::BeginMap << YAML::Key << "base" << YAML::Value << f.time_base;
  e << YAML::Key << "column" << YAML::Value << f.time_column;
  e << YAML::Key << "unit" << YAML::Value
    << unit_of_scale(f.time_scale_s, {{1.0, "s"}, {1e-3, "ms"}, {1e-6, "us"}, {1e-9, "ns"}});
  if (f.gps_week >= 0) e << YAML::Key << "gps_week" << YAML::Value << f.gps_week;
  if (f.start_epoch) {
    e << YAML::Key << "start_gps_week" << YAML::Value << f.start_epoch->week() << YAML::Key << "start_gps_tow_s"
      << YAML::Value << yaml_number(f.start_epoch->tow_s());
  }
  if (f.index_rate_hz > 0) e << YAML::Key << "rate_hz" << YAML::Value << yaml_number(f.index_rate_hz);
  e << YAML::EndMap;
  e << YAML::Key << "gyro" << YAML::Value << YAML::BeginMap << YAML::Key << "columns" << YAML::Value << YAML::Flow
    << columns(f.gyro_columns) << YAML::Key << "unit" << YAML::Value << f.gyro_unit << YAML::Key << "signs"
    << YAML::Value << YAML::Flow << signs(f.gyro_signs) << YAML::Key << "full_scale_deg_per_s" << YAML::Value
    << yaml_number(f.gyro_full_scale * kRadToDeg) << YAML::EndMap;
  e << YAML::Key << "accel" << YAML::Value << YAML::BeginMap << YAML::Key << "columns" << YAML::Value << YAML::Flow
    << columns(f.accel_columns) << YAML::Key << "unit" << YAML::Value << f.accel_unit << YAML::Key << "signs"
    << YAML::Value << YAML::Flow << signs(f.accel_signs) << YAML::Key << "full_scale_g" << YAML::Value
    << yaml_number(f.accel_full_scale / kG0) << YAML::EndMap;
  if (f.stance_column >= 0) {
    e << YAML::Key << "stance" << YAML::Value << YAML::BeginMap << YAML::Key << "column" << YAML::Value
      << f.stance_column << YAML::EndMap;
  }
  if (f.mag_columns[0] >= 0) {
    e << YAML::Key << "mag" << YAML::Value << YAML::BeginMap << YAML::Key << "columns" << YAML::Value << YAML::Flow
      << columns(f.mag_columns) << YAML::Key << "unit" << YAML::Value
      << unit_of_scale(f.mag_scale_to_ut, {{1.0, "ut"}, {100.0, "gauss"}, {0.1, "mgauss"}, {1e-3, "nt"}}) << YAML::Key
      << "signs" << YAML::Value << YAML::Flow << signs(f.mag_signs) << YAML::EndMap;
  }
  if (!f.R_b_s.isIdentity(0.0)) {
    // The angles as read when they give this R_b_s (a format built in code may set R_b_s alone).
    const Eigen::Vector3d& a = f.mounting_rpy_deg;
    const bool as_read = R_n_b_from_euler(a.x() * kDegToRad, a.y() * kDegToRad, a.z() * kDegToRad) == f.R_b_s;
    const Eigen::Vector3d rpy_deg = as_read ? a : Eigen::Vector3d(euler_from_R_n_b(f.R_b_s) * kRadToDeg);
    e << YAML::Key << "mounting_rpy_deg" << YAML::Value << YAML::Flow
      << yaml_numbers({rpy_deg.x(), rpy_deg.y(), rpy_deg.z()});
  }
  e << YAML::Key << "max_gap_s" << YAML::Value << yaml_number(f.max_gap_s);
  e << YAML::Key << "gap_factor" << YAML::Value << yaml_number(f.gap_factor);
  e << YAML::Key << "rest_tolerance_mps2" << YAML::Value << yaml_number(f.rest_tolerance_mps2);
  e << YAML::EndMap;
}

}  // namespace pednav::io
