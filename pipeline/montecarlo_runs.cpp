// SPDX-License-Identifier: BSD-2-Clause
// The run files of `pednav montecarlo` (pipeline/montecarlo_runs.hpp).
#include "pipeline/montecarlo_runs.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "io/atomic_file.hpp"

namespace pednav::pipeline {
namespace {

// Per-run file: a '#' header line with the run facts, then one row per epoch and solution.
constexpr const char* kRunHeader =
    "solution,t_s,distance_m,err_n_m,err_e_m,err_d_m,cov_nn_m2,cov_ne_m2,cov_nd_m2,cov_ee_m2,cov_ed_m2,cov_dd_m2,"
    "err_yaw_rad,var_yaw_rad2";

}  // namespace

std::string run_file(const std::string& out, int i) {
  char b[32];
  std::snprintf(b, sizeof b, "run_%04d.csv", i);
  return (std::filesystem::path(out) / "runs" / b).string();
}

Expected<void> write_run(const std::string& path, const RunRecord& r) {
  std::ostringstream o;
  o.precision(17);  // lossless: a run read back (resume, shard merge) aggregates to the same bits as one in memory
  std::string msg = r.message;
  std::replace(msg.begin(), msg.end(), '\n', ' ');
  o << "# index=" << r.index << " seed=" << r.seed << " ok=" << r.ok << " wall_s=" << r.wall_s
    << " distance_m=" << r.distance_m;
  const eval::McCarrierRun& c = r.run.carrier;
  if (c.gnss_epochs > 0) {
    o << " gnss_epochs=" << c.gnss_epochs << " fixed_epochs=" << c.fixed_epochs
      << " wrong_fixed_epochs=" << c.wrong_fixed_epochs << " antenna_nees_sum=" << c.antenna_nees_sum
      << " time_to_first_fix_s=" << c.time_to_first_fix_s;
  }
  o << " message=" << msg << "\n" << kRunHeader << "\n";
  for (int k = 0; k < 2; ++k) {
    for (const auto& e : k == 0 ? r.run.forward : r.run.smoothed) {
      const auto& C = e.cov_ned_m2;
      o << (k == 0 ? "forward" : "smoothed") << ',' << e.t_s << ',' << e.distance_m << ',' << e.err_ned_m.x() << ','
        << e.err_ned_m.y() << ',' << e.err_ned_m.z() << ',' << C(0, 0) << ',' << C(0, 1) << ',' << C(0, 2) << ','
        << C(1, 1) << ',' << C(1, 2) << ',' << C(2, 2) << ',' << e.err_yaw_rad << ',' << e.var_yaw_rad2 << '\n';
    }
  }
  return io::write_file_atomic(path, o.str());
}

Expected<RunRecord> read_run(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line) || line.rfind("# index=", 0) != 0) return make_error(path + ":1: expected '# index=...'");
  RunRecord r;
  auto field = [&](const std::string& key) {
    const auto p = line.find(" " + key + "=");
    if (p == std::string::npos) return std::string();
    const auto b = p + key.size() + 2;
    const auto e = key == "message" ? std::string::npos : line.find(' ', b);
    return line.substr(b, e == std::string::npos ? std::string::npos : e - b);
  };
  r.index = std::atoi(line.substr(8).c_str());
  r.seed = std::strtoull(field("seed").c_str(), nullptr, 10);
  r.ok = field("ok") == "1";
  r.wall_s = std::atof(field("wall_s").c_str());
  r.distance_m = std::atof(field("distance_m").c_str());
  r.message = field("message");
  if (const std::string n = field("gnss_epochs"); !n.empty()) {  // a carrier study's run
    eval::McCarrierRun& c = r.run.carrier;
    c.gnss_epochs = std::atoi(n.c_str());
    c.fixed_epochs = std::atoi(field("fixed_epochs").c_str());
    c.wrong_fixed_epochs = std::atoi(field("wrong_fixed_epochs").c_str());
    c.antenna_nees_sum = std::atof(field("antenna_nees_sum").c_str());
    c.time_to_first_fix_s = std::atof(field("time_to_first_fix_s").c_str());
  }
  std::getline(in, line);  // column header
  long row = 2;
  while (std::getline(in, line)) {
    ++row;
    std::stringstream ss(line);
    std::string sol, cell;
    std::getline(ss, sol, ',');
    std::vector<double> v;
    while (std::getline(ss, cell, ',')) v.push_back(std::atof(cell.c_str()));
    if (v.size() != 13 || (sol != "forward" && sol != "smoothed")) {
      return make_error(path + ":" + std::to_string(row) + ": expected 14 columns (" + kRunHeader + ")");
    }
    eval::McEpoch e;
    e.t_s = v[0];
    e.distance_m = v[1];
    e.err_ned_m = Eigen::Vector3d(v[2], v[3], v[4]);
    e.cov_ned_m2 << v[5], v[6], v[7], v[6], v[8], v[9], v[7], v[9], v[10];
    e.err_yaw_rad = v[11];
    e.var_yaw_rad2 = v[12];
    (sol == "forward" ? r.run.forward : r.run.smoothed).push_back(e);
  }
  return r;
}

}  // namespace pednav::pipeline
