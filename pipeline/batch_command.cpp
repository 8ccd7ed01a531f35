// SPDX-License-Identifier: BSD-2-Clause
// `pednav batch` (pipeline/batch_command.hpp).
#include "pipeline/batch_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <charconv>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "io/atomic_file.hpp"
#include "io/config.hpp"
#include "pipeline/gnss_command.hpp"
#include "pipeline/outage_command.hpp"
#include "pipeline/run_command.hpp"

namespace pednav::pipeline {
namespace {

namespace fs = std::filesystem;

bool valid_name(const std::string& n) {
  if (n.empty() || n == "." || n == "..") return false;
  for (char c : n) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) return false;
  }
  return true;
}

std::string csv_cell(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  if (s.find_first_of(",\"") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// keep_sats of a manifest (CSV cell or YAML scalar): an integer >= 0; any other text, a fraction or a value beyond int
// is an error (std::from_chars reports overflow, where std::atoi's result is undefined).
bool parse_keep_sats(std::string s, int& out) {
  s.erase(0, s.find_first_not_of(" \t"));
  s.erase(s.find_last_not_of(" \t\r") + 1);
  int v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || end != s.data() + s.size() || v < 0) return false;
  out = v;
  return true;
}

// The accuracy figures of an item's evaluation.json (empty when it has none).
std::string accuracy_cells(const fs::path& dir) {
  std::ifstream in(dir / "evaluation.json");
  if (!in) return ",,,";
  const auto j = nlohmann::json::parse(in, nullptr, false);
  if (j.is_discarded()) return ",,,";
  auto num = [&](const char* k) { return j.contains(k) && j[k].is_number() ? fmt::format("{:.3f}", j[k].get<double>()) : std::string(); };
  return fmt::format("{},{},{},{}", j.value("epochs_compared", 0), num("horizontal_rms_m"), num("horizontal_p95_m"),
                     num("horizontal_max_m"));
}

Expected<void> run_item(const BatchItem& it, const std::string& out) {
  auto cfg = io::load_run_config(it.config);
  if (!cfg) return cfg.error();
  if (it.command == "run") {
    if (!it.mode.empty()) cfg->mode = it.mode;
    auto r = run_run_command(*cfg, out);
    if (!r) return r.error();
  } else if (it.command == "gnss") {
    auto r = run_gnss_command(*cfg, out);
    if (!r) return r.error();
  } else {
    OutageArgs a;
    a.out_dir = out;
    a.keep_sats = it.keep_sats;
    a.plot = false;
    auto r = run_outage_command(*cfg, a);
    if (!r) return r.error();
  }
  return {};
}

}  // namespace

Expected<std::vector<BatchItem>> read_batch_manifest(const std::string& path) {
  std::ifstream in(path);
  if (!in) return make_error(path + ": cannot read the manifest");
  const fs::path base = fs::absolute(path).parent_path();
  std::vector<BatchItem> items;
  std::vector<std::string> problems;
  auto finish = [&](BatchItem b, const std::string& where) {
    if (!valid_name(b.name)) problems.push_back(where + ": name '" + b.name + "' (letters, digits, - _ . only)");
    if (b.command != "run" && b.command != "gnss" && b.command != "outage")
      problems.push_back(where + ": command '" + b.command + "' (expected run, gnss or outage)");
    if (b.config.empty()) problems.push_back(where + ": config missing");
    if (!b.mode.empty() && b.mode != "tc" && b.mode != "ins") problems.push_back(where + ": mode '" + b.mode + "' (tc or ins)");
    if (!b.config.empty() && fs::path(b.config).is_relative()) b.config = (base / b.config).lexically_normal().string();
    if (!b.config.empty() && !fs::exists(b.config)) problems.push_back(where + ": config " + b.config + " does not exist");
    items.push_back(std::move(b));
  };
  if (fs::path(path).extension() == ".csv") {
    std::string line;
    std::getline(in, line);
    std::vector<std::string> head;
    {
      std::stringstream ss(line);
      for (std::string c; std::getline(ss, c, ',');) head.push_back(c);
    }
    long n = 1;
    while (std::getline(in, line)) {
      ++n;
      if (line.empty() || line[0] == '#') continue;
      std::vector<std::string> cells;
      std::stringstream ss(line);
      for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
      BatchItem b;
      for (size_t i = 0; i < head.size() && i < cells.size(); ++i) {
        if (head[i] == "name") b.name = cells[i];
        else if (head[i] == "command") b.command = cells[i];
        else if (head[i] == "config") b.config = cells[i];
        else if (head[i] == "mode") b.mode = cells[i];
        else if (head[i] == "keep_sats" && !parse_keep_sats(cells[i], b.keep_sats))
          problems.push_back(path + ":" + std::to_string(n) + ": keep_sats: expected an integer >= 0, got '" +
                             cells[i] + "'");
      }
      finish(std::move(b), path + ":" + std::to_string(n));
    }
  } else {
    YAML::Node root;
    try {
      root = YAML::LoadFile(path);
    } catch (const YAML::Exception& e) {
      return make_error(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
    }
    if (!root["items"] || !root["items"].IsSequence()) return make_error(path + ": expected `items:` a list");
    int k = 0;
    for (const auto& n : root["items"]) {
      ++k;
      const std::string where = path + ": items[" + std::to_string(k) + "]";
      if (!n.IsMap()) {
        problems.push_back(where + ": expected a mapping");
        continue;
      }
      BatchItem b;
      for (const auto& kv : n) {
        const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
        const std::string value = kv.second.IsScalar() ? kv.second.Scalar() : std::string();
        const bool known = key == "name" || key == "command" || key == "config" || key == "mode" || key == "keep_sats";
        if (!known) {
          problems.push_back(where + ": unknown key '" + key + "'");
          continue;
        }
        if (!kv.second.IsScalar()) {
          problems.push_back(where + ": " + key + ": expected a " + (key == "keep_sats" ? "number" : "string"));
          continue;
        }
        if (key == "name") b.name = value;
        else if (key == "command") b.command = value;
        else if (key == "config") b.config = value;
        else if (key == "mode") b.mode = value;
        else if (!parse_keep_sats(value, b.keep_sats))
          problems.push_back(where + ": keep_sats: expected an integer >= 0, got '" + value + "'");
      }
      finish(std::move(b), where);
    }
  }
  std::set<std::string> names;
  for (const auto& b : items) {
    if (!names.insert(b.name).second) problems.push_back(path + ": name '" + b.name + "' used twice");
  }
  if (items.empty()) problems.push_back(path + ": no items");
  if (!problems.empty()) {
    std::string all;
    for (const auto& p : problems) all += (all.empty() ? "" : "\n") + p;
    return make_error(all);
  }
  return items;
}

Expected<BatchResult> run_batch_command(const std::string& manifest, const std::string& out_dir, int shard_index,
                                        int shard_count) {
  if (shard_count < 1 || shard_index < 1 || shard_index > shard_count)
    return make_error(fmt::format("--shard {}/{}: expected K/N with 1 <= K <= N", shard_index, shard_count));
  auto items = read_batch_manifest(manifest);
  if (!items) return items.error();
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) return make_error(out_dir + ": cannot create the output folder: " + ec.message());
  BatchResult res;
  std::string index = "name,command,config,status,error\n";
  std::string summary = "name,command,status,epochs_compared,horizontal_rms_m,horizontal_p95_m,horizontal_max_m\n";
  for (size_t i = 0; i < items->size(); ++i) {
    if (static_cast<int>(i % static_cast<size_t>(shard_count)) != shard_index - 1) continue;
    const BatchItem& it = (*items)[i];
    const fs::path dir = fs::path(out_dir) / it.name;
    const fs::path status_file = dir / "batch_status.json";
    ++res.items;
    std::string status, error;
    if (std::ifstream in(status_file); in) {  // resume: a finished item is not redone
      const auto j = nlohmann::json::parse(in, nullptr, false);
      if (!j.is_discarded() && j.value("status", "") == "ok") {
        status = "ok";
        ++res.skipped_done;
      }
    }
    if (status.empty()) {
      const auto t0 = std::chrono::steady_clock::now();
      spdlog::info("batch: {} ({} {})", it.name, it.command, it.config);
      auto r = run_item(it, dir.string());
      status = r ? "ok" : "failed";
      if (!r) error = r.error().message.substr(0, r.error().message.find('\n'));
      fs::create_directories(dir, ec);
      nlohmann::ordered_json j = {{"name", it.name}, {"command", it.command}, {"config", it.config},
                                  {"status", status}, {"error", error},
                                  {"wall_s", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
      // Written last and atomically: an item killed before this line is redone on the next invocation.
      if (auto w = io::write_file_atomic(status_file.string(), j.dump(2) + "\n"); !w) return w.error();
      if (!r) spdlog::warn("batch: {} failed: {}", it.name, error);
    } else if (std::ifstream in(status_file); in) {
      error = nlohmann::json::parse(in, nullptr, false).value("error", "");
    }
    (status == "ok" ? res.ok : res.failed) += 1;
    index += fmt::format("{},{},{},{},{}\n", csv_cell(it.name), it.command, csv_cell(it.config), status, csv_cell(error));
    summary += fmt::format("{},{},{},{}\n", csv_cell(it.name), it.command, status,
                           status == "ok" ? accuracy_cells(dir) : std::string(",,,"));
  }
  if (auto w = io::write_file_atomic((fs::path(out_dir) / "index.csv").string(), index); !w) return w.error();
  if (auto w = io::write_file_atomic((fs::path(out_dir) / "summary.csv").string(), summary); !w) return w.error();
  res.table = summary;
  return res;
}

}  // namespace pednav::pipeline
