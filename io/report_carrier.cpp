// SPDX-License-Identifier: BSD-2-Clause
// report.html's carrier-phase section (issue 48 item 7, docs/carrier.md §6): the solution status of each epoch of
// solution.csv or gnss.csv (fixed / float / code / ins, with the number of fixed ambiguities) over time and along the track, and
// the share of each status with the time to the first fix.
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <fstream>
#include <map>

#include "io/plot_figures.hpp"
#include "io/report_internal.hpp"

namespace pednav::io::report_detail {
namespace {

struct StatusStyle {
  const char* name;
  double level;  // y of the status plot
  const char* color;
};
constexpr std::array<StatusStyle, 4> kStatuses{{{"fixed", 3.0, "#2ca02c"},
                                                {"float", 2.0, "#ff7f0e"},
                                                {"code", 1.0, "#1f77b4"},
                                                {"ins", 0.0, "#7f7f7f"}}};

struct StatusEpoch {
  double t_s;          // since the report's t0
  Eigen::Vector3d p_e;
  int status;          // index into kStatuses
  double n_fixed;
};

double cell_number(const std::vector<std::string>& cells, int k) {
  if (k < 0 || k >= static_cast<int>(cells.size())) return NAN;
  const std::string c = trim(cells[static_cast<size_t>(k)]);
  char* end = nullptr;
  const double v = c.empty() ? NAN : std::strtod(c.c_str(), &end);
  return (c.empty() || *end != '\0') ? NAN : v;
}

}  // namespace

bool carrier_status_section(Html& h, const fs::path& csv, GpsTime t0, const Eigen::Vector3d& p0_e) {
  std::ifstream in(csv);
  std::string line;
  if (!in || !std::getline(in, line)) return false;
  std::map<std::string, int> col;
  const auto head = split(line);
  for (size_t k = 0; k < head.size(); ++k) col[trim(head[k])] = static_cast<int>(k);
  for (const char* need : {"solution_status", "gps_week", "gps_tow_s", "x_m", "y_m", "z_m"}) {
    if (!col.count(need)) return false;  // a run without carrier phase: no section
  }
  const int ks = col["solution_status"];
  const int kn = col.count("n_fixed_ambiguities") ? col["n_fixed_ambiguities"] : -1;
  std::vector<StatusEpoch> ep;
  long unknown = 0;
  while (std::getline(in, line)) {
    const auto cells = split(line);
    if (ks >= static_cast<int>(cells.size())) continue;
    const std::string s = trim(cells[static_cast<size_t>(ks)]);
    if (s.empty()) continue;  // an epoch before the carrier filter ran
    int status = -1;
    for (size_t i = 0; i < kStatuses.size(); ++i) status = s == kStatuses[i].name ? static_cast<int>(i) : status;
    const double wk = cell_number(cells, col["gps_week"]), tow = cell_number(cells, col["gps_tow_s"]);
    const Eigen::Vector3d p(cell_number(cells, col["x_m"]), cell_number(cells, col["y_m"]),
                            cell_number(cells, col["z_m"]));
    if (status < 0 || !std::isfinite(wk) || !std::isfinite(tow) || !p.allFinite()) {
      ++unknown;
      continue;
    }
    ep.push_back({GpsTime::from_week_tow(static_cast<int>(wk), tow) - t0, p, status, cell_number(cells, kn)});
  }
  if (ep.empty()) return false;

  h.section("Carrier-phase solution status");
  std::vector<PlotSeries> over_time;
  std::vector<EnTrack> along;
  std::vector<std::vector<std::string>> rows;
  for (size_t i = 0; i < kStatuses.size(); ++i) {
    PlotSeries s{kStatuses[i].name, PlotStyle::kPoints, {}, {}, {}, {}, kStatuses[i].color, 0.8};
    std::vector<Eigen::Vector3d> p;
    double first = NAN;
    for (const auto& e : ep) {
      if (e.status != static_cast<int>(i)) continue;
      s.x.push_back(e.t_s);
      s.y.push_back(kStatuses[i].level);
      p.push_back(e.p_e);
      if (!std::isfinite(first)) first = e.t_s;
    }
    rows.push_back({kStatuses[i].name, fmt::format("{}", s.x.size()),
                    fmt::format("{:.1f} %", 100.0 * static_cast<double>(s.x.size()) / static_cast<double>(ep.size())),
                    std::isfinite(first) ? fmt::format("{:.1f}", first) : "–"});
    if (s.x.empty()) continue;
    over_time.push_back(std::move(s));
    EnTrack t = to_en_track(kStatuses[i].name, p, p0_e, kStatuses[i].color);
    t.style = PlotStyle::kPoints;
    along.push_back(std::move(t));
  }
  PlotSeries fixed{"fixed ambiguities", PlotStyle::kSteps, {}, {}, {}, {}, "#2ca02c", 1.2};
  for (const auto& e : ep) {
    fixed.x.push_back(e.t_s);
    fixed.y.push_back(std::isfinite(e.n_fixed) ? e.n_fixed : 0.0);
  }
  const std::string file = csv.filename().string();
  h.para(fmt::format("{} epochs of {} carry a status (docs/carrier.md §6: fixed = integer ambiguities "
                     "held, float = phase rows with float ambiguities, code = code and Doppler only, ins = no GNSS "
                     "row at the epoch){}.",
                     ep.size(), file, unknown ? fmt::format("; {} rows without a readable status or position", unknown) : ""));
  h.table({"status", "epochs", "share", "first at [s]"}, rows);
  h.row_open();
  PlotSpec st{"Solution status over time", "time since start [s]", "status: 0 ins, 1 code, 2 float, 3 fixed",
              over_time};
  st.y_min = -0.5;
  st.y_max = 3.5;
  h.plot(st, "The status of each output epoch (" + file + " solution_status).");
  h.plot(trajectory_plot("Track by solution status", along),
         "The track of " + file + " in local East/North, each epoch coloured by its status.");
  h.row_close();
  PlotSpec nf{"Fixed ambiguities", "time since start [s]", "ambiguities", {fixed}};
  nf.y_from_zero = true;
  h.plot(nf, "Number of fixed ambiguities at each output epoch (" + file + " n_fixed_ambiguities).");
  return true;
}

}  // namespace pednav::io::report_detail
