// SPDX-License-Identifier: BSD-2-Clause
#include "io/rinex_summary.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

namespace pednav::io {

Expected<gnss::SystemSelection> parse_systems(const std::string& letters) {
  gnss::SystemSelection s{false, false, false, false, false};
  for (char c : letters) {
    switch (c) {
      case 'G': s.gps = true; break;
      case 'R': s.glonass = true; break;
      case 'E': s.galileo = true; break;
      case 'C': s.beidou = true; break;
      case 'J': s.qzss = true; break;
      default: return make_error(fmt::format("systems '{}': unknown constellation letter '{}' (expected G R E C J)", letters, c));
    }
  }
  return s;
}

Expected<std::string> summarize_rinex_obs(const std::string& path, const std::string& systems) {
  auto sel = parse_systems(systems);
  if (!sel) return sel.error();
  auto obs = gnss::read_rinex_obs(path, *sel);
  if (!obs) return obs.error();
  const auto& ep = obs->epochs;
  std::map<char, std::set<int>> sats;
  size_t n_meas = 0, n_doppler = 0, n_cn0 = 0;
  for (const auto& e : ep) {
    for (const auto& s : e.sats) {
      sats[gnss::system_letter(s.sat.system)].insert(s.sat.prn);
      ++n_meas;
      if (!std::isnan(s.doppler_hz)) ++n_doppler;
      if (!std::isnan(s.cn0_dbhz)) ++n_cn0;
    }
  }
  std::vector<double> dts;
  for (size_t i = 1; i < ep.size(); ++i) dts.push_back(ep[i].time - ep[i - 1].time);
  std::sort(dts.begin(), dts.end());
  std::string out = fmt::format("file: {}\nreceiver: {}\nmarker: {}\n", path, obs->receiver_type, obs->marker_name);
  out += fmt::format("epochs: {}\nfirst: {}\nlast: {}\n", ep.size(), ep.front().time.to_string(), ep.back().time.to_string());
  if (!dts.empty()) {
    out += fmt::format("interval_s: median {:.3f}, min {:.3f}, max {:.3f}\n", dts[dts.size() / 2], dts.front(), dts.back());
  }
  if (obs->has_approx_position) {
    out += fmt::format("approx_position_ecef_m: [{:.4f}, {:.4f}, {:.4f}]\n", obs->approx_position_e.x(),
                       obs->approx_position_e.y(), obs->approx_position_e.z());
  }
  for (const auto& [sys, prns] : sats) out += fmt::format("satellites_{}: {}\n", sys, prns.size());
  out += fmt::format("measurements: {} (with Doppler {}, with C/N0 {})\n", n_meas, n_doppler, n_cn0);
  return out;
}

}  // namespace pednav::io
