// SPDX-License-Identifier: BSD-2-Clause
// Evaluation against the configured reference (pipeline/reference_evaluation.hpp).
#include "pipeline/reference_evaluation.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <set>

#include "eval/statistics.hpp"
#include "eval/trajectory.hpp"
#include "io/atomic_file.hpp"
#include "pipeline/compare_command.hpp"

namespace pednav::pipeline {

using namespace pednav::io;

Expected<TrajectoryFile> read_configured_reference(const RunConfig& c) {
  TrajectoryReadOptions ro;
  auto fmt_ = parse_trajectory_format(c.reference.format);
  if (fmt_) ro.format = *fmt_;
  ro.nmea_qualities = std::set<int>(c.reference.nmea_qualities.begin(), c.reference.nmea_qualities.end());
  return read_trajectory(c.reference.file, ro);
}

Expected<nlohmann::json> evaluate_rows(const std::vector<SolutionRow>& rows, const TrajectoryFile& reference,
                                       const std::string& reference_name, const std::string& csv_path,
                                       const std::string& json_path, const std::string& what) {
  auto ev = evaluate_rows_text(rows, reference, reference_name, csv_path, what);
  if (!ev) return ev.error();
  if (auto ok = write_file_atomic(json_path, ev->json_text); !ok) return ok.error();
  return ev->figures;
}

Expected<RowsEvaluation> evaluate_rows_text(const std::vector<SolutionRow>& rows, const TrajectoryFile& reference,
                                            const std::string& reference_name, const std::string& csv_path,
                                            const std::string& what) {
  eval::Trajectory sol;
  for (const auto& r : rows) {
    const Eigen::Vector3d sd_enu(std::sqrt(r.cov_p_n(1, 1)), std::sqrt(r.cov_p_n(0, 0)), std::sqrt(r.cov_p_n(2, 2)));
    sol.points.push_back({r.time, r.p_e, sd_enu});
  }
  auto ev = eval::compare(sol, reference.trajectory, eval::CompareOptions{});
  if (!ev) return make_error("evaluation against " + reference_name + ": " + ev.error().message);
  CompareArgs args;
  args.solution = csv_path;
  args.reference = reference_name;
  TrajectoryFile sf;
  sf.format = "csv";
  sf.trajectory = sol;
  RowsEvaluation out;
  out.json_text = evaluation_json(*ev, args, sf, reference);
  spdlog::info("{} vs reference: horizontal RMS {:.2f} m, p95 {:.2f} m, max {:.2f} m, {:.1f} % < 5 m", what,
               ev->horizontal_rms_m, ev->horizontal_p95_m, ev->horizontal_max_m, ev->bins_pct[0]);
  out.figures = nlohmann::json{{"horizontal_rms_m", ev->horizontal_rms_m}, {"horizontal_max_m", ev->horizontal_max_m},
                               {"availability_pct", ev->availability_pct}, {"lt5_pct", ev->bins_pct[0]},
                               {"inside_3sigma_pct", eval::consistency_statistics(ev->errors).inside_3sigma_pct}};
  return out;
}

bool has_carrier_phase(const gnss::ObsData& obs) {
  for (const auto& e : obs.epochs) {
    for (const auto& s : e.sats) {
      if (std::isfinite(s.carrier_cycles)) return true;
    }
  }
  return false;
}

std::string carrier_unavailable(const GnssConfig& g, const gnss::ObsData& rover, const gnss::ObsData* base) {
  const auto has_phase = has_carrier_phase;
  if (!base) return "no base_obs (the carrier needs a base)";
  if (!has_phase(rover)) return g.rover_obs + " has no L1 carrier phase";
  if (!has_phase(*base)) return g.base_obs + " has no L1 carrier phase";
  return "";
}

fusion::AmbiguityOptions ambiguity_options(const GnssConfig& g) {
  const auto& a = g.ambiguity;
  fusion::AmbiguityOptions o;
  o.ratio_threshold = a.ratio_threshold;
  o.min_success_rate = a.min_success_rate;
  o.ar_elevation_mask_rad = a.elevation_mask_deg * kDegToRad;
  o.partial = a.partial;
  o.min_ambiguities = a.min_ambiguities;
  o.min_lock_epochs = a.min_lock_epochs;
  o.hold = a.hold;
  o.hold_min_epochs = a.hold_min_epochs;
  o.hold_sigma_cycles = a.hold_sigma_cycles;
  o.validation_w = a.validation_w;
  o.glonass = a.glonass;
  o.glonass_ifb_search = a.glonass_ifb == "search";
  return o;
}

}  // namespace pednav::pipeline
