// SPDX-License-Identifier: BSD-2-Clause
#include "io/yaml_schema.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/geodesy.hpp"

namespace pednav::io {
namespace {

// A key that is absent (or explicitly null) reads as "not given".
bool absent(const YAML::Node& n) { return !n.IsDefined() || n.IsNull(); }

std::string describe(const YAML::Node& n) {
  if (absent(n)) return "nothing";
  if (n.IsMap()) return "a mapping";
  if (n.IsSequence()) return "a list";
  return "'" + n.Scalar() + "'";
}

bool parse_double(const YAML::Node& n, double& out) {
  if (!n.IsScalar()) return false;
  const std::string& s = n.Scalar();
  if (s.empty()) return false;
  std::istringstream is(s);
  is.imbue(std::locale::classic());
  is >> out;
  return !is.fail() && is.eof() && std::isfinite(out);
}

}  // namespace

std::string yaml_number(double v) {
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v > 0 ? ".inf" : "-.inf";
  return fmt::format("{}", v);  // fmt's shortest round-trip form (Dragonbox)
}

std::string yaml_degrees(double radians) {
  if (!std::isfinite(radians)) return yaml_number(radians * kRadToDeg);
  const double deg = radians * kRadToDeg;
  for (int digits = 1; digits <= 17; ++digits) {
    const std::string s = fmt::format("{:.{}g}", deg, digits);
    if (std::stod(s) * kDegToRad == radians) return yaml_number(std::stod(s));
  }
  return yaml_number(deg);
}

std::vector<std::string> yaml_numbers(std::initializer_list<double> v) {
  std::vector<std::string> out;
  for (double x : v) out.push_back(yaml_number(x));
  return out;
}

Expected<YamlSource> read_yaml_source(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) return make_error(path + ": cannot open " + what);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::filesystem::path p(path);
  return YamlSource{ss.str(), p.parent_path().empty() ? "." : p.parent_path().string()};
}

void YamlProblems::add(const YAML::Node& where, const std::string& path, const std::string& what) {
  std::string loc = file;
  if (where.IsDefined() && where.Mark().line >= 0) loc += ":" + std::to_string(where.Mark().line + 1);
  messages.push_back(loc + ": " + path + ": " + what);
}

std::string YamlProblems::joined() const {
  std::string s;
  for (size_t i = 0; i < messages.size(); ++i) s += (i ? "\n" : "") + messages[i];
  return s;
}

YamlMap::YamlMap(YAML::Node node, std::string path, std::shared_ptr<YamlProblems> problems,
                 std::filesystem::path base_dir)
    : node_(std::move(node)), path_(std::move(path)), problems_(std::move(problems)), base_dir_(std::move(base_dir)) {
  if (!absent(node_) && !node_.IsMap()) {
    problems_->add(node_, path_.empty() ? "(top level)" : path_, "expected a mapping, got " + describe(node_));
    node_ = YAML::Node();
  }
}

YamlMap::~YamlMap() { finish(); }

std::string YamlMap::key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

bool YamlMap::has(const std::string& key) const {
  const YAML::Node& n = node_;
  return n.IsDefined() && n.IsMap() && !absent(n[key]);
}

YAML::Node YamlMap::get(const std::string& key, bool required) {
  if (known_.insert(key).second) {
    // The key's path with list indices written as "[]" ("route.waypoints[3].e_m" -> "route.waypoints[].e_m").
    std::string p = key_path(key), normalized;
    for (size_t i = 0; i < p.size(); ++i) {
      normalized += p[i];
      if (p[i] == '[') {
        while (i + 1 < p.size() && p[i + 1] != ']') ++i;
      }
    }
    problems_->keys_read.insert(std::move(normalized));
  }
  if (!has(key)) {
    if (required) problems_->add(node_, key_path(key), "required key is missing");
    return YAML::Node(YAML::NodeType::Undefined);
  }
  const YAML::Node& n = node_;
  return n[key];
}

YamlMap YamlMap::map(const std::string& key, bool required) {
  return YamlMap(get(key, required), key_path(key), problems_, base_dir_);
}

void YamlMap::number(const std::string& key, double& out, bool required, double min, double max) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return;
  double v = 0.0;
  if (!parse_double(n, v)) {
    problems_->add(n, key_path(key), "expected a finite number, got " + describe(n));
    return;
  }
  if (v < min || v > max) {
    std::ostringstream os;
    os << "value " << v << " is out of range [" << min << ", " << max << "]";
    problems_->add(n, key_path(key), os.str());
    return;
  }
  out = v;
}

bool YamlMap::integer_of(const YAML::Node& n, const std::string& key, int min, int max, int& out) {
  double v = 0.0;
  if (!parse_double(n, v) || v != std::floor(v)) {
    problems_->add(n, key_path(key), "expected an integer, got " + describe(n));
    return false;
  }
  // Compared as a double: only a value inside [min, max] is converted (a double beyond int is undefined behaviour).
  if (v < min || v > max) {
    problems_->add(n, key_path(key),
                   "value " + n.Scalar() + " is out of range [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    return false;
  }
  out = static_cast<int>(v);
  return true;
}

void YamlMap::integer(const std::string& key, int& out, bool required, int min, int max) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return;
  int v = 0;
  if (integer_of(n, key, min, max, v)) out = v;
}

bool YamlMap::integers(const std::string& key, std::vector<int>& out, int min, int max, bool required) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return !required;
  if (!n.IsSequence()) {
    problems_->add(n, key_path(key), "expected a list of integers, got " + describe(n));
    return false;
  }
  out.clear();
  bool ok = true;
  for (const auto& item : n) {
    int v = 0;
    if (integer_of(item, key, min, max, v)) {
      out.push_back(v);
    } else {
      ok = false;
    }
  }
  return ok;
}

void YamlMap::boolean(const std::string& key, bool& out, bool required) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return;
  const std::string s = n.IsScalar() ? n.Scalar() : "";
  if (s == "true" || s == "True" || s == "yes" || s == "on") {
    out = true;
  } else if (s == "false" || s == "False" || s == "no" || s == "off") {
    out = false;
  } else {
    problems_->add(n, key_path(key), "expected true or false, got " + describe(n));
  }
}

void YamlMap::text(const std::string& key, std::string& out, bool required) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return;
  if (!n.IsScalar()) {
    problems_->add(n, key_path(key), "expected a string, got " + describe(n));
    return;
  }
  out = n.Scalar();
}

void YamlMap::choice(const std::string& key, std::string& out, std::initializer_list<const char*> allowed,
                     bool required) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return;
  std::string options;
  for (const char* a : allowed) {
    if (n.IsScalar() && n.Scalar() == a) {
      out = a;
      return;
    }
    options += std::string(options.empty() ? "" : ", ") + a;
  }
  problems_->add(n, key_path(key), "expected one of {" + options + "}, got " + describe(n));
}

void YamlMap::path(const std::string& key, std::string& out, bool required) {
  std::string s;
  text(key, s, required);
  if (s.empty()) return;
  std::filesystem::path p(s);
  out = (p.is_absolute() ? p : base_dir_ / p).lexically_normal().string();
}

void YamlMap::paths(const std::string& key, std::vector<std::string>& out, bool required) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return;
  out.clear();
  auto add = [&](const YAML::Node& item) {
    if (!item.IsScalar() || item.Scalar().empty()) {
      problems_->add(item, key_path(key), "expected a path, got " + describe(item));
      return;
    }
    std::filesystem::path p(item.Scalar());
    out.push_back((p.is_absolute() ? p : base_dir_ / p).lexically_normal().string());
  };
  if (n.IsSequence()) {
    for (const auto& item : n) add(item);
  } else {
    add(n);
  }
}

void YamlMap::strings(const std::string& key, std::vector<std::string>& out, bool required) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return;
  if (!n.IsSequence()) {
    problems_->add(n, key_path(key), "expected a list of strings, got " + describe(n));
    return;
  }
  out.clear();
  for (const auto& item : n) {
    if (!item.IsScalar()) {
      problems_->add(item, key_path(key), "expected a string, got " + describe(item));
      continue;
    }
    out.push_back(item.Scalar());
  }
}

void YamlMap::numbers(const std::string& key, std::vector<double>& out, bool required) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return;
  if (!n.IsSequence()) {
    problems_->add(n, key_path(key), "expected a list of numbers, got " + describe(n));
    return;
  }
  out.clear();
  for (const auto& item : n) {
    double v = 0.0;
    if (!parse_double(item, v)) {
      problems_->add(item, key_path(key), "expected a finite number, got " + describe(item));
      continue;
    }
    out.push_back(v);
  }
}

void YamlMap::vector3(const std::string& key, Eigen::Vector3d& out, bool required) {
  const YAML::Node n = get(key, required);
  if (absent(n)) return;
  std::vector<double> v;
  if (n.IsSequence() && n.size() == 3) {
    for (const auto& item : n) {
      double x = 0.0;
      if (parse_double(item, x)) v.push_back(x);
    }
  }
  if (v.size() != 3) {
    problems_->add(n, key_path(key), "expected a list of 3 numbers, got " + describe(n));
    return;
  }
  out = Eigen::Vector3d(v[0], v[1], v[2]);
}

YAML::Node YamlMap::raw(const std::string& key) { return get(key, false); }

void YamlMap::problem(const std::string& key, const std::string& what) {
  problems_->add(has(key) ? node_[key] : node_, key_path(key), what);
}

void YamlMap::finish() {
  if (finished_) return;
  finished_ = true;
  if (absent(node_) || !node_.IsMap()) return;
  // yaml-cpp keeps every pair of a mapping but looks up the first: a repeated key would be silently ignored.
  std::map<std::string, int> first_line;
  for (const auto& kv : node_) {
    const std::string k = kv.first.as<std::string>("");
    if (const auto [it, inserted] = first_line.emplace(k, kv.first.Mark().line + 1); !inserted) {
      problems_->add(kv.first, key_path(k), "duplicate key (first at line " + std::to_string(it->second) + ")");
      continue;
    }
    if (!known_.count(k)) problems_->add(kv.first, key_path(k), "unknown key");
  }
}

}  // namespace pednav::io
