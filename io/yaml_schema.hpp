// SPDX-License-Identifier: BSD-2-Clause
// Strict YAML mapping reader: every problem (unknown key, wrong type, missing key, out of range) is collected
// with its file:line and YAML path, so a config is rejected with all of its problems at once.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "core/expected.hpp"

namespace pednav::io {

/// The text of a YAML file, and the folder its relative paths are resolved against.
struct YamlSource {
  std::string text;
  std::string base_dir;
};
/// Read a whole YAML file; the error is "<path>: cannot open <what>" (what: "configuration file", ...).
Expected<YamlSource> read_yaml_source(const std::string& path, const std::string& what);

/// A double as YAML text: the shortest decimal that reads back to the same double ("0.1", where yaml-cpp's emitter
/// writes 0.10000000000000001); .inf, -.inf, .nan for the others. Emit it as a scalar: `e << yaml_number(v)`.
std::string yaml_number(double v);
/// A value the reader converts from degrees (`key_deg…: v` → v · π/180): the shortest decimal v that the reader turns
/// back into the same radians (60 for 60 · π/180, not 59.99999999999999).
std::string yaml_degrees(double radians);
/// The same for a list (a flow sequence of numbers: `e << YAML::Flow << yaml_numbers({x, y, z})`).
std::vector<std::string> yaml_numbers(std::initializer_list<double> v);

/// Problems found while reading one YAML file.
struct YamlProblems {
  std::string file;
  std::vector<std::string> messages;
  /// Every key path a YamlMap marked as known while reading ("gnss.ambiguity.partial"; the items of a list as
  /// "route.waypoints[].e_m"): the vocabulary the reader accepts on the branches the file took.
  std::set<std::string> keys_read;
  void add(const YAML::Node& where, const std::string& path, const std::string& what);
  bool empty() const { return messages.empty(); }
  std::string joined() const;  ///< one problem per line
};

/// A view of one YAML mapping at a path ("imu.spec"). Keys read through it are marked as known; finish()
/// reports every other key as unknown.
class YamlMap {
 public:
  YamlMap(YAML::Node node, std::string path, std::shared_ptr<YamlProblems> problems,
          std::filesystem::path base_dir);
  ~YamlMap();
  YamlMap(YamlMap&&) = default;
  YamlMap(const YamlMap&) = delete;
  YamlMap& operator=(const YamlMap&) = delete;

  bool has(const std::string& key) const;
  /// Child mapping; an absent optional child is an empty mapping.
  YamlMap map(const std::string& key, bool required = false);

  void number(const std::string& key, double& out, bool required = false, double min = -1e300, double max = 1e300);
  /// An integer in [min, max]; a fraction or a value outside the range (however large) is reported, never cast.
  void integer(const std::string& key, int& out, bool required = false, int min = -2147483647, int max = 2147483647);
  /// A list of integers, each in [min, max] (each bad item reported with its line); false if any was reported.
  bool integers(const std::string& key, std::vector<int>& out, int min, int max, bool required = false);
  void boolean(const std::string& key, bool& out, bool required = false);
  void text(const std::string& key, std::string& out, bool required = false);
  /// A string that must be one of `allowed`.
  void choice(const std::string& key, std::string& out, std::initializer_list<const char*> allowed,
              bool required = false);
  /// A path, resolved relative to the config file's folder.
  void path(const std::string& key, std::string& out, bool required = false);
  /// A path or a list of paths.
  void paths(const std::string& key, std::vector<std::string>& out, bool required = false);
  void strings(const std::string& key, std::vector<std::string>& out, bool required = false);
  void numbers(const std::string& key, std::vector<double>& out, bool required = false);
  void vector3(const std::string& key, Eigen::Vector3d& out, bool required = false);
  /// Mark a key as known without reading it (the caller reads the node itself).
  YAML::Node raw(const std::string& key);
  /// Report an out-of-range/inconsistent value of a key that was already read.
  void problem(const std::string& key, const std::string& what);
  /// Report unknown keys (called by the destructor if not called explicitly).
  void finish();
  const std::string& yaml_path() const { return path_; }

 private:
  YAML::Node get(const std::string& key, bool required);
  /// n as an integer in [min, max] into out; false (problem reported under key) if it is not one.
  bool integer_of(const YAML::Node& n, const std::string& key, int min, int max, int& out);
  std::string key_path(const std::string& key) const;

  YAML::Node node_;
  std::string path_;
  std::shared_ptr<YamlProblems> problems_;
  std::filesystem::path base_dir_;
  std::set<std::string> known_;
  bool finished_ = false;
};

}  // namespace pednav::io
