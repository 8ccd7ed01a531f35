// SPDX-License-Identifier: BSD-2-Clause
// pednav_solution_dump CONFIG.yaml [--mode tc|ins]: runs the engine on a run configuration exactly as `pednav run`
// does (io::load_run_config → pipeline::load_run_inputs → fusion::run_forward, GNSS row records on as in run) and
// prints every forward and smoothed output epoch at full precision on stdout, for scripts/solution_reference (the
// 1e-6 m / 1e-6 deg regression test, ctest regression.solution_1e6). solution.csv prints positions to 0.1 mm and
// attitude to 1e-4 deg, too coarse for that test.
//
// Output, one record per line, space separated:
//   F|S tow_s n_m e_m d_m roll_deg pitch_deg yaw_deg n_sats_used n_sats_rejected
//       F: forward epoch (solution.csv), S: smoothed epoch (smoothed.csv); position of the IMU as NED metres from
//       the first forward epoch's position (local level frame at that point), attitude as in solution.csv.
//   R tow_s sat code|doppler w_final
//       a GNSS row the forward filter's w-test rejected, with its last w-statistic (docs/fusion.md §6.1).
#include <cstdio>
#include <cstring>
#include <string>

#include "core/geodesy.hpp"
#include "io/config.hpp"
#include "pipeline/run_command.hpp"

int main(int argc, char** argv) {
  using namespace pednav;
  if (argc != 2 && !(argc == 4 && std::strcmp(argv[2], "--mode") == 0)) {
    std::fprintf(stderr, "usage: %s CONFIG.yaml [--mode tc|ins]\n", argv[0]);
    return 2;
  }
  auto cfg = io::load_run_config(argv[1]);
  if (!cfg) {
    std::fprintf(stderr, "%s\n", cfg.error().message.c_str());
    return 1;
  }
  if (argc == 4) cfg->mode = argv[3];
  auto loaded = pipeline::load_run_inputs(*cfg);
  if (!loaded) {
    std::fprintf(stderr, "%s\n", loaded.error().message.c_str());
    return 1;
  }
  fusion::EngineOptions opt = loaded->options;
  opt.record_gnss_rows = opt.mode == fusion::Mode::kTightlyCoupled;  // as pednav run (residuals.csv)
  auto res = fusion::run_forward(loaded->engine_inputs(), opt);
  if (!res) {
    std::fprintf(stderr, "%s\n", res.error().message.c_str());
    return 1;
  }
  if (res->epochs.empty()) return 0;
  const Eigen::Vector3d p_ref_e = res->epochs.front().nav.p_eb_e;
  auto print = [&](char kind, const fusion::EpochOutput& e) {
    const io::SolutionRow row = pipeline::solution_row(e);
    const Eigen::Vector3d ned = ned_from_ecef(row.p_e, p_ref_e);
    const Eigen::Vector3d rpy = row.rpy_deg.value_or(Eigen::Vector3d::Zero());
    std::printf("%c %.3f %.9f %.9f %.9f %.9f %.9f %.9f %d %d\n", kind, e.t.tow_s(), ned.x(), ned.y(), ned.z(), rpy.x(),
                rpy.y(), rpy.z(), row.n_sats_used, row.n_sats_rejected);
  };
  for (const auto& e : res->epochs) print('F', e);
  for (const auto& e : res->smoothed) print('S', e);
  for (const auto& r : res->gnss_rows) {
    if (r.rejected) {
      std::printf("R %.3f %s %s %.6f\n", r.t.tow_s(), r.sat.to_string().c_str(), r.doppler ? "doppler" : "code",
                  r.w_final);
    }
  }
  return 0;
}
