// SPDX-License-Identifier: BSD-2-Clause
// `pednav gnss`: read rover/base/nav, match epochs, solve each epoch, write gnss.csv, gnss.pos, summary.json.
#include "pipeline/gnss_command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "core/geodesy.hpp"
#include "gnss/ephemeris.hpp"
#include "gnss/least_squares.hpp"
#include "gnss/rtklib/rinex.hpp"
#include "io/atomic_file.hpp"
#include "io/log.hpp"
#include "io/solution_writer.hpp"
#include "pipeline/reference_evaluation.hpp"

namespace pednav::pipeline {

using namespace pednav::io;  // the readers, writers and configuration this use case drives
namespace {

gnss::SystemSelection selection(const std::vector<std::string>& systems) {
  gnss::SystemSelection s;
  s.gps = false;
  for (const auto& l : systems) {
    if (l == "G") s.gps = true;
    if (l == "R") s.glonass = true;
    if (l == "E") s.galileo = true;
    if (l == "C") s.beidou = true;
    if (l == "J") s.qzss = true;
  }
  return s;
}

// Error when the nav data has no ephemeris valid anywhere in the rover span for any observed satellite.
Expected<void> check_nav_covers(const gnss::NavData& nav, const gnss::ObsData& rover, const std::string& nav_names) {
  const GpsTime t0 = rover.epochs.front().time, t1 = rover.epochs.back().time;
  for (const GpsTime t : {t0, GpsTime::from_ns((t0.ns() + t1.ns()) / 2), t1}) {
    // The epoch nearest t with observations.
    for (const auto& e : rover.epochs) {
      if (e.time < t) continue;
      int ok = 0;
      for (const auto& s : e.sats) ok += gnss::satellite_state(nav, s.sat, t).has_value();
      if (ok == 0 && !e.sats.empty()) {
        GpsTime lo = GpsTime::from_ns(INT64_MAX), hi = GpsTime::from_ns(INT64_MIN);
        for (const auto& k : nav.kepler) lo = std::min(lo, k.toe), hi = std::max(hi, k.toe);
        for (const auto& g : nav.glonass) lo = std::min(lo, g.toe), hi = std::max(hi, g.toe);
        return make_error(nav_names + ": navigation data do not cover the rover span " + t0.to_string() + " .. " +
                          t1.to_string() + " (ephemeris toe " + lo.to_string() + " .. " + hi.to_string() +
                          "; no satellite of the epoch at " + e.time.to_string() + " has a valid ephemeris)");
      }
      break;
    }
  }
  return {};
}

std::string json_number(double v) { return std::isfinite(v) ? fmt::format("{:.4f}", v) : "null"; }

// summary.json `carrier.glonass_ifb` (docs/carrier.md eq. 3.11): with GLONASS, gnss.ambiguity.glonass_ifb: search
// (the default) and glonass: false.
std::string glonass_ifb_json(const GnssRunSummary& s, const RunConfig& c) {
  const auto& sys = c.gnss.systems;
  if (c.gnss.ambiguity.glonass_ifb != "search" || c.gnss.ambiguity.glonass ||
      std::find(sys.begin(), sys.end(), "R") == sys.end()) {
    return "";
  }
  const auto& r = s.rtk;
  return fmt::format(", \"glonass_ifb\": {{\"m_per_channel\": {}, \"found_s\": {}, \"searches\": {}, \"votes\": {}}}",
                     r.glonass_ifb_m_per_channel ? fmt::format("{:.5f}", *r.glonass_ifb_m_per_channel) : "null",
                     r.glonass_ifb_found_s ? json_number(*r.glonass_ifb_found_s) : "null", r.glonass_ifb_searches,
                     r.glonass_ifb_votes);
}

std::string summary_json(const GnssRunSummary& s, const RunConfig& c) {
  std::string j = "{\n";
  j += fmt::format("  \"mode\": \"{}\",\n", s.differential ? "single_difference" : "undifferenced");
  j += fmt::format("  \"epochs_read\": {},\n  \"epochs_solved\": {},\n  \"epochs_with_velocity\": {},\n",
                   s.epochs_read, s.epochs_solved, s.epochs_with_velocity);
  j += fmt::format("  \"solved_pct\": {},\n",
                   json_number(s.epochs_read ? 100.0 * s.epochs_solved / s.epochs_read : 0.0));
  auto map_json = [](const std::map<std::string, int>& m) {
    std::string o = "{";
    bool first = true;
    for (const auto& [k, v] : m) o += fmt::format("{}\"{}\": {}", first ? "" : ", ", k, v), first = false;
    return o + "}";
  };
  j += "  \"epochs_not_solved\": " + map_json(s.not_solved) + ",\n";
  j += "  \"satellites_rejected\": " + map_json(s.satellites_rejected) + ",\n";
  j += fmt::format("  \"event_records_skipped\": {{\"rover\": {}, \"base\": {}}},\n", s.rover_event_records,
                   s.base_event_records);
  if (s.differential) {
    const auto& a = s.base_age;
    j += fmt::format(
        "  \"base_age_s\": {{\"matched_epochs\": {}, \"simultaneous_epochs\": {}, \"unmatched_epochs\": {}, "
        "\"mean\": {}, \"median\": {}, \"p95\": {}, \"max\": {}, \"histogram\": {{\"le_tolerance\": {}, "
        "\"to_1\": {}, \"1_to_2\": {}, \"2_to_5\": {}, \"5_to_10\": {}, \"10_to_30\": {}, \"gt_30\": {}}}}},\n",
        a.matched, a.simultaneous, a.unmatched, json_number(a.mean_s), json_number(a.median_s),
        json_number(a.p95_s), json_number(a.max_s), a.histogram[0], a.histogram[1], a.histogram[2],
        a.histogram[3], a.histogram[4], a.histogram[5], a.histogram[6]);
    j += fmt::format("  \"base_position_source\": \"{}\",\n", s.base_position_from_header ? "rinex_header" : "config");
    j += fmt::format("  \"base_propagation\": \"{}\",\n", c.gnss.base_propagation);
  }
  auto sm = [](const gnss::CodeSmoothingStats& x) {
    return fmt::format("{{\"smoothed\": {}, \"restarts_gap\": {}, \"restarts_jump\": {}, \"clock_jumps\": {}}}", x.smoothed,
                       x.restarts_gap, x.restarts_jump, x.clock_jumps);
  };
  j += fmt::format("  \"code_smoothing\": {{\"window_s\": {}, \"rover\": {}, \"base\": {}}},\n",
                   json_number(c.gnss.code_smoothing_s), sm(s.smoothing_rover), sm(s.smoothing_base));
  if (s.carrier) {
    const auto& r = s.rtk;
    std::string slips = "{";
    for (int k = 0; k < static_cast<int>(gnss::SlipReason::kCount); ++k) {
      slips += fmt::format("{}\"{}\": {}", k ? ", " : "", gnss::slip_reason_name(static_cast<gnss::SlipReason>(k)),
                           r.slips[k]);
    }
    slips += "}";
    j += fmt::format(
        "  \"carrier\": {{\"used\": true, \"epochs\": {}, \"fixed\": {}, \"float\": {}, \"code\": {}, \"none\": {}, "
        "\"fix_rate_pct\": {}, \"time_to_first_fix_s\": {}, \"fix_attempts\": {}, \"not_fixed\": {}, "
        "\"fixes_rejected_by_validation\": {}, \"wrong_fix_detections\": {}, \"holds\": {}, \"slips\": {}, "
        "\"code_rows_excluded\": {}, \"doppler_rows_excluded\": {}{}}},\n",
        r.epochs, r.fixed, r.float_, r.code, r.none, json_number(r.epochs ? 100.0 * r.fixed / r.epochs : 0.0),
        r.time_to_first_fix_s ? json_number(*r.time_to_first_fix_s) : "null", r.fix_attempts, map_json(r.not_fixed),
        r.fixes_rejected_by_validation, r.wrong_fix_detections, r.holds, slips, r.code_rows_excluded,
        r.doppler_rows_excluded, glonass_ifb_json(s, c));
  }
  if (s.tdcp) {
    const auto& t = s.tdcp_summary;
    std::string slips = "{";
    for (int k = 0; k < static_cast<int>(gnss::SlipReason::kCount); ++k) {
      slips += fmt::format("{}\"{}\": {}", k ? ", " : "", gnss::slip_reason_name(static_cast<gnss::SlipReason>(k)),
                           t.slips[k]);
    }
    slips += "}";
    j += fmt::format(
        "  \"carrier\": {{\"used\": true, \"mode\": \"tdcp\", \"epochs\": {}, \"solved\": {}, \"tdcp_epochs\": {}, "
        "\"tdcp_rows\": {}, \"slips\": {}, \"code_rows_excluded\": {}, \"doppler_rows_excluded\": {}}},\n",
        t.epochs, t.solved, t.tdcp_epochs, t.tdcp_rows, slips, t.code_rows_excluded, t.doppler_rows_excluded);
  }
  j += fmt::format("  \"wall_s\": {}\n}}\n", json_number(s.wall_s));
  return j;
}

// The configured constellations, in gnss.systems' order (one clock state each).
std::vector<gnss::System> rtk_systems(const GnssConfig& g) {
  std::vector<gnss::System> out;
  for (const auto& l : g.systems) {
    if (l == "G") out.push_back(gnss::System::kGps);
    if (l == "R") out.push_back(gnss::System::kGlonass);
    if (l == "E") out.push_back(gnss::System::kGalileo);
    if (l == "C") out.push_back(gnss::System::kBeidou);
    if (l == "J") out.push_back(gnss::System::kQzss);
  }
  return out;
}

// A gnss.csv row from a kinematic filter's epoch (RtkEpoch, TdcpEpoch): time, position, velocity and position
// covariance in the local level frame, satellites used and rejected.
template <typename Epoch>
SolutionRow filter_row(const Epoch& e) {
  SolutionRow row;
  row.time = e.time;
  row.p_e = e.p_ea_e;
  const Geodetic llh = geodetic_from_ecef(e.p_ea_e);
  const Eigen::Matrix3d R_ne = R_e_n(llh.lat, llh.lon).transpose();
  row.v_n = R_ne * e.v_ea_e;
  row.cov_p_n = R_ne * e.cov_p_e * R_ne.transpose();
  row.n_sats_used = e.n_sats;
  row.n_sats_rejected = e.n_rejected;
  return row;
}

}  // namespace

Expected<GnssRunSummary> run_gnss_command(const RunConfig& config, const std::string& out_dir) {
  const auto start = std::chrono::steady_clock::now();
  if (const auto missing = missing_input_files(config); !missing.empty()) {
    std::string all;
    for (const auto& m : missing) all += (all.empty() ? "" : "; ") + m;
    return make_error(config.source_file + ": " + all);
  }
  const GnssConfig& g = config.gnss;
  if (g.rover_obs.empty()) return make_error(config.source_file + ": rover_obs is required for pednav gnss");
  if (g.nav.empty()) return make_error(config.source_file + ": nav is required for pednav gnss");
  const gnss::SystemSelection sel = selection(g.systems);

  auto rover = gnss::read_rinex_obs(g.rover_obs, sel);
  if (!rover) return rover.error();
  if (rover->stats.truncated) {
    return make_error(g.rover_obs + ": truncated: the last epoch record is incomplete (file cut off?)");
  }
  std::optional<gnss::ObsData> base;
  if (!g.base_obs.empty()) {
    auto b = gnss::read_rinex_obs(g.base_obs, sel);
    if (!b) return b.error();
    if (b->stats.truncated) return make_error(g.base_obs + ": truncated: the last epoch record is incomplete");
    base = std::move(*b);
  }
  auto nav = gnss::read_rinex_nav(g.nav);
  if (!nav) return nav.error();
  std::string nav_names;
  for (const auto& n : g.nav) nav_names += (nav_names.empty() ? "" : ", ") + n;
  if (auto ok = check_nav_covers(*nav, *rover, nav_names); !ok) return ok.error();

  GnssRunSummary sum;
  if (g.code_smoothing_s > 0.0) {
    gnss::CodeSmoothingOptions so;
    so.window_s = g.code_smoothing_s;
    sum.smoothing_rover = gnss::smooth_code_with_doppler(rover->epochs, so);
    if (base) sum.smoothing_base = gnss::smooth_code_with_doppler(base->epochs, so);
  }
  sum.epochs_read = static_cast<int>(rover->epochs.size());
  sum.rover_event_records = rover->stats.event_records;
  sum.differential = base.has_value();

  Eigen::Vector3d p_base = Eigen::Vector3d::Zero();
  std::vector<gnss::BaseMatch> matches(rover->epochs.size());
  if (base) {
    sum.base_event_records = base->stats.event_records;
    if (g.base_position_ecef_m) {
      p_base = *g.base_position_ecef_m;
    } else if (base->has_approx_position) {
      p_base = base->approx_position_e;
      sum.base_position_from_header = true;
      spdlog::warn("{}: base position taken from the RINEX header APPROX POSITION XYZ ({:.3f}, {:.3f}, {:.3f}) m; "
                   "it is approximate: set base_position_ecef_m for accurate results",
                   g.base_obs, p_base.x(), p_base.y(), p_base.z());
    } else {
      return make_error(g.base_obs + ": no base position: the RINEX header has no APPROX POSITION XYZ and "
                        "base_position_ecef_m is not set in " + config.source_file);
    }
    std::vector<GpsTime> rt, bt;
    for (const auto& e : rover->epochs) rt.push_back(e.time);
    for (const auto& e : base->epochs) bt.push_back(e.time);
    matches = gnss::match_base_epochs(rt, bt, g.max_base_age_s);
    sum.base_age = gnss::age_statistics(matches, g.epoch_match_tolerance_s);
    if (sum.base_age.matched == 0) {
      return make_error(g.base_obs + ": no base epoch within max_base_age_s = " + fmt::format("{}", g.max_base_age_s) +
                        " s of any rover epoch (base " + bt.front().to_string() + " .. " + bt.back().to_string() +
                        ", rover " + rt.front().to_string() + " .. " + rt.back().to_string() +
                        "): base file from another day or time?");
    }
    // Common satellites at all?
    bool any_common = false;
    for (size_t i = 0; i < matches.size() && !any_common; ++i) {
      if (matches[i].base_index < 0) continue;
      for (const auto& rs : rover->epochs[i].sats) {
        for (const auto& bs : base->epochs[matches[i].base_index].sats) any_common |= rs.sat == bs.sat;
      }
    }
    if (!any_common) {
      return make_error(g.rover_obs + " and " + g.base_obs +
                        ": no common satellites in any matched epoch (check gnss.systems and the files)");
    }
  }

  gnss::SolverOptions opt;
  opt.elevation_mask_rad = g.elevation_mask_rad;
  opt.min_cn0_dbhz = g.min_cn0_dbhz;
  opt.fault_probability = config.fault_rejection_probability;
  opt.weights.code_sigma_zenith_m = g.code_sigma_zenith_m;
  opt.weights.doppler_sigma_zenith_mps = g.doppler_sigma_zenith_mps;
  opt.weights.cn0_ref_dbhz = g.cn0_ref_dbhz;
  opt.weights.glonass_code_factor = g.glonass_code_factor;
  opt.weights.elevation_weight = g.elevation_weight;
  opt.weights.code_squaring_loss = g.code_squaring_loss;

  std::vector<SolutionRow> rows;
  rows.reserve(rover->epochs.size());
  // Carrier phase (docs/carrier.md §4): with a base and L1 phase in both files, unless gnss.carrier: off.
  if (g.carrier != "off") {
    if (base) {
      sum.carrier_note = carrier_unavailable(g, *rover, &*base);
      sum.carrier = sum.carrier_note.empty();
    } else if (has_carrier_phase(*rover)) {
      sum.tdcp = true;  // a rover alone: its phase differenced over time (docs/carrier.md §9)
    } else {
      sum.carrier_note = g.rover_obs + " has no L1 carrier phase";
    }
    if (sum.carrier || sum.tdcp) {
      // the phase is used
    } else if (g.carrier == "on") {
      return make_error(config.source_file + ": gnss.carrier: on, but " + sum.carrier_note);
    } else {
      spdlog::info("gnss.carrier auto: {}: code and Doppler only", sum.carrier_note);
    }
  }
  if (sum.carrier) {
    fusion::RtkOptions ro;
    ro.systems = rtk_systems(g);
    ro.elevation_mask_rad = g.elevation_mask_rad;
    ro.min_cn0_dbhz = g.min_cn0_dbhz;
    ro.weights = opt.weights;
    ro.fault_probability = opt.fault_probability;
    ro.use_doppler = g.use_doppler;
    ro.carrier_sigma_zenith_m = g.carrier_sigma_zenith_m;
    ro.base_age_sigma_mps = g.carrier_base_age_sigma_mps;
    ro.accel_sigma_horizontal_mps2 = g.rtk_accel_sigma_horizontal_mps2;
    ro.accel_sigma_vertical_mps2 = g.rtk_accel_sigma_vertical_mps2;
    ro.ar = ambiguity_options(g);
    fusion::RtkFilter rtk(*nav, base->epochs, p_base, ro);
    Progress progress("gnss rtk", static_cast<int64_t>(rover->epochs.size()), progress_enabled());
    for (size_t i = 0; i < rover->epochs.size(); ++i) {
      progress.update(static_cast<int64_t>(i));
      const fusion::RtkEpoch e = rtk.process(rover->epochs[i], matches[i].base_index);
      if (e.status == fusion::SolutionStatus::kNone) {
        ++sum.not_solved[matches[i].base_index < 0 ? gnss::epoch_failure_name(gnss::EpochFailure::kNoBaseEpoch)
                                                   : gnss::epoch_failure_name(gnss::EpochFailure::kTooFewSatellites)];
        continue;
      }
      ++sum.epochs_solved;
      ++sum.epochs_with_velocity;
      SolutionRow row = filter_row(e);
      row.pos_quality = fusion::pos_quality(e.status);
      row.age_s = e.base_age_s;
      row.solution_status = fusion::solution_status_name(e.status);
      row.n_fixed_ambiguities = e.n_fixed;
      row.ar_ratio = e.ratio;
      rows.push_back(row);
    }
    progress.finish();
    sum.rtk = rtk.summary();
  }
  if (sum.tdcp) {
    fusion::TdcpOptions to;
    to.systems = rtk_systems(g);
    to.elevation_mask_rad = g.elevation_mask_rad;
    to.min_cn0_dbhz = g.min_cn0_dbhz;
    to.weights = opt.weights;
    to.fault_probability = opt.fault_probability;
    to.use_doppler = g.use_doppler;
    to.carrier_sigma_zenith_m = g.carrier_sigma_zenith_m;
    to.accel_sigma_horizontal_mps2 = g.rtk_accel_sigma_horizontal_mps2;
    to.accel_sigma_vertical_mps2 = g.rtk_accel_sigma_vertical_mps2;
    fusion::TdcpFilter tdcp(*nav, to);
    Progress progress("gnss tdcp", static_cast<int64_t>(rover->epochs.size()), progress_enabled());
    for (size_t i = 0; i < rover->epochs.size(); ++i) {
      progress.update(static_cast<int64_t>(i));
      const fusion::TdcpEpoch e = tdcp.process(rover->epochs[i]);
      if (!e.ok) {
        ++sum.not_solved[gnss::epoch_failure_name(gnss::EpochFailure::kTooFewSatellites)];
        continue;
      }
      ++sum.epochs_solved;
      ++sum.epochs_with_velocity;
      SolutionRow row = filter_row(e);
      row.pos_quality = 5;
      rows.push_back(row);
    }
    progress.finish();
    sum.tdcp_summary = tdcp.summary();
  }
  for (int r = 0; r < static_cast<int>(gnss::RejectReason::kCount); ++r) {
    sum.satellites_rejected[gnss::reject_reason_name(static_cast<gnss::RejectReason>(r))] = 0;
  }
  Eigen::Vector3d p_prev = Eigen::Vector3d::Zero();
  Progress progress("gnss", static_cast<int64_t>(rover->epochs.size()), progress_enabled());
  for (size_t i = 0; i < rover->epochs.size() && !sum.carrier && !sum.tdcp; ++i) {
    progress.update(static_cast<int64_t>(i));
    const gnss::ObsEpoch& re = rover->epochs[i];
    gnss::EpochSolution sol;
    std::optional<gnss::ObsEpoch> propagated;
    const gnss::ObsEpoch* be = nullptr;
    if (base) {
      if (matches[i].base_index < 0) {
        ++sum.not_solved[gnss::epoch_failure_name(gnss::EpochFailure::kNoBaseEpoch)];
        continue;
      }
      be = &base->epochs[matches[i].base_index];
      if (g.base_propagation == "doppler" && std::abs(matches[i].age_s) > g.epoch_match_tolerance_s) {
        propagated = gnss::propagate_base_with_doppler(*be, re.time);
        be = &*propagated;
      }
    }
    sol = gnss::solve_epoch(*nav, re, be, p_base, p_prev, opt);
    for (int r = 0; r < static_cast<int>(gnss::RejectReason::kCount); ++r) {
      sum.satellites_rejected[gnss::reject_reason_name(static_cast<gnss::RejectReason>(r))] += sol.rejections[r];
    }
    if (!sol.ok()) {
      ++sum.not_solved[gnss::epoch_failure_name(sol.failure)];
      continue;
    }
    ++sum.epochs_solved;
    p_prev = sol.p_ea_e;
    SolutionRow row;
    row.time = re.time;
    row.p_e = sol.p_ea_e;
    const Geodetic llh = geodetic_from_ecef(sol.p_ea_e);
    const Eigen::Matrix3d R_ne = R_e_n(llh.lat, llh.lon).transpose();
    if (sol.velocity_ok) {
      row.v_n = R_ne * sol.v_ea_e;
      ++sum.epochs_with_velocity;
    }
    row.cov_p_n = R_ne * sol.cov_p_e * R_ne.transpose();
    row.n_sats_used = sol.n_sats_used;
    row.n_sats_rejected = sol.n_sats_rejected;
    row.pos_quality = base ? 4 : 5;
    row.age_s = base ? matches[i].age_s : 0.0;
    row.hdop = sol.dops.hdop;
    row.pdop = sol.dops.pdop;
    rows.push_back(row);
  }
  progress.finish();

  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return make_error(out_dir + ": cannot create the output folder: " + ec.message());
  const std::string dir = out_dir + "/";
  if (auto ok = write_solution_csv(dir + "gnss.csv", rows); !ok) return ok.error();
  std::vector<std::string> comment{"pednav gnss " + config.source_file,
                                   std::string("mode        : ") + (sum.carrier ? "kinematic RTK (SD code, Doppler, L1 phase)"
                                                                    : sum.tdcp ? "kinematic, undifferenced code and Doppler, time-differenced L1 phase"
                                                                    : base     ? "single-differenced code (DGPS)"
                                                                               : "undifferenced code (single)")};
  if (auto ok = write_solution_pos(dir + "gnss.pos", rows, comment); !ok) return ok.error();
  if (!config.reference.file.empty()) {
    auto ref = read_configured_reference(config);
    if (!ref) return ref.error();
    auto figures = evaluate_rows(rows, *ref, config.reference.file, dir + "gnss.csv", dir + "evaluation.json", "gnss");
    if (!figures) return figures.error();
    sum.evaluation = *figures;
  }
  sum.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (auto ok = write_file_atomic(dir + "summary.json", summary_json(sum, config)); !ok) return ok.error();
  return sum;
}

}  // namespace pednav::pipeline
