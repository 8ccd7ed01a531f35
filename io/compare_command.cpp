#include "io/compare_command.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/atomic_file.hpp"

namespace pednav::io {
namespace {

const char* align_name(eval::Align a) {
  switch (a) {
    case eval::Align::kStart: return "start";
    case eval::Align::kBestFit2d: return "best-fit-2d";
    case eval::Align::kBestFit3d: return "best-fit-3d";
    default: return "none";
  }
}

}  // namespace

std::string evaluation_json(const eval::Evaluation& ev, const CompareArgs& args, const TrajectoryFile& sol,
                            const TrajectoryFile& ref) {
  nlohmann::ordered_json j;
  j["epochs_compared"] = ev.epochs_compared;
  j["availability_pct"] = ev.availability_pct;
  j["horizontal_rms_m"] = ev.horizontal_rms_m;
  j["horizontal_mean_m"] = ev.horizontal_mean_m;
  j["horizontal_p50_m"] = ev.horizontal_p50_m;
  j["horizontal_p95_m"] = ev.horizontal_p95_m;
  j["horizontal_max_m"] = ev.horizontal_max_m;
  j["vertical_rms_m"] = ev.vertical_rms_m;
  j["vertical_mean_m"] = ev.vertical_mean_m;
  j["vertical_max_abs_m"] = ev.vertical_max_abs_m;
  j["bins_pct"] = {{"lt5", ev.bins_pct[0]}, {"5to10", ev.bins_pct[1]}, {"10to20", ev.bins_pct[2]}, {"ge20", ev.bins_pct[3]}};
  if (ev.has_closure) {
    j["closure_m"] = ev.closure_m;
    j["closure_pct_of_distance"] = ev.closure_pct_of_distance;
    j["distance_m"] = ev.distance_m;
  }
  j["reference_epochs"] = ev.reference_epochs;
  j["align"] = align_name(args.compare.align);
  j["time_tolerance_s"] = args.compare.time_tolerance_s;
  j["solution"] = {{"file", args.solution}, {"format", sol.format}, {"epochs", sol.trajectory.points.size()}};
  j["reference"] = {{"file", args.reference},
                    {"format", ref.format},
                    {"epochs", ref.trajectory.points.size()},
                    {"skipped_quality", ref.skipped_quality},
                    {"skipped_checksum", ref.skipped_checksum},
                    {"skipped_empty", ref.skipped_empty},
                    {"skipped_duplicate_time", ref.skipped_duplicate_time}};
  return j.dump(2) + "\n";
}

std::string evaluation_markdown(const eval::Evaluation& ev, const CompareArgs& args) {
  std::string s = fmt::format("# Evaluation\n\nSolution `{}` against reference `{}` (alignment: {}).\n\n", args.solution,
                              args.reference, align_name(args.compare.align));
  s += "| figure | value |\n|---|---|\n";
  s += fmt::format("| epochs compared | {} |\n| availability | {:.1f} % |\n", ev.epochs_compared, ev.availability_pct);
  s += fmt::format("| horizontal RMS | {:.3f} m |\n| horizontal mean | {:.3f} m |\n| horizontal p50 | {:.3f} m |\n",
                   ev.horizontal_rms_m, ev.horizontal_mean_m, ev.horizontal_p50_m);
  s += fmt::format("| horizontal p95 | {:.3f} m |\n| horizontal max | {:.3f} m |\n| vertical RMS | {:.3f} m |\n",
                   ev.horizontal_p95_m, ev.horizontal_max_m, ev.vertical_rms_m);
  if (ev.has_closure) {
    s += fmt::format("| closure | {:.3f} m ({:.2f} % of {:.1f} m) |\n", ev.closure_m, ev.closure_pct_of_distance,
                     ev.distance_m);
  }
  s += "\nHorizontal error distribution (layout of seed 004 Tables 1-2):\n\n| < 5 m | 5-10 m | 10-20 m | ≥ 20 m |\n|---|---|---|---|\n";
  s += fmt::format("| {:.1f} % | {:.1f} % | {:.1f} % | {:.1f} % |\n", ev.bins_pct[0], ev.bins_pct[1], ev.bins_pct[2],
                   ev.bins_pct[3]);
  return s;
}

Expected<eval::Evaluation> run_compare(const CompareArgs& args) {
  auto sol = read_trajectory(args.solution, args.solution_read);
  if (!sol) return sol.error();
  auto ref = read_trajectory(args.reference, args.reference_read);
  if (!ref) return ref.error();
  auto ev = eval::compare(sol->trajectory, ref->trajectory, args.compare);
  if (!ev) return make_error(args.solution + " vs " + args.reference + ": " + ev.error().message);
  std::error_code ec;
  std::filesystem::create_directories(args.out_dir, ec);
  if (ec) return make_error(args.out_dir + ": cannot create output folder: " + ec.message());
  const std::filesystem::path out(args.out_dir);
  if (auto ok = write_file_atomic((out / "evaluation.json").string(), evaluation_json(*ev, args, *sol, *ref)); !ok) {
    return ok.error();
  }
  if (auto ok = write_file_atomic((out / "evaluation.md").string(), evaluation_markdown(*ev, args)); !ok) {
    return ok.error();
  }
  std::string csv = "gps_week,gps_tow_s,de_m,dn_m,du_m,horizontal_m\n";
  for (const auto& e : ev->errors) {
    csv += fmt::format("{},{:.3f},{:.4f},{:.4f},{:.4f},{:.4f}\n", e.t.week(), e.t.tow_s(), e.d_enu.x(), e.d_enu.y(),
                       e.d_enu.z(), e.horizontal_m);
  }
  if (auto ok = write_file_atomic((out / "errors.csv").string(), csv); !ok) return ok.error();
  return ev;
}

}  // namespace pednav::io
