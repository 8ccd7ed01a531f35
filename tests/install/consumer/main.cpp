// SPDX-License-Identifier: BSD-2-Clause
// Uses an installed pednav as a library: loads a scenario, simulates it in memory, runs the INS/ZUPT engine from the
// true start and prints the final horizontal error. Exit 0 when the run succeeded and closes within 1 % of the walk.
#include <cmath>
#include <cstdio>

#include "core/geodesy.hpp"
#include "core/rotation.hpp"
#include "fusion/engine.hpp"
#include "io/scenario_config.hpp"
#include "sim/simulator.hpp"

int main(int argc, char** argv) {
  using namespace pednav;
  if (argc < 2) {
    std::fprintf(stderr, "usage: consumer SCENARIO.yaml\n");
    return 2;
  }
  auto file = io::load_scenario(argv[1]);
  if (!file) {
    std::fprintf(stderr, "%s\n", file.error().message.c_str());
    return 1;
  }
  auto s = sim::simulate(file->scenario);
  if (!s) {
    std::fprintf(stderr, "%s\n", s.error().message.c_str());
    return 1;
  }
  fusion::EngineOptions o;
  o.mode = fusion::Mode::kInsOnly;
  o.spec = file->scenario.imu.spec;
  o.smoother_enabled = false;
  const ins::NavState& t0 = s->truth.nav.front();
  o.initial_position_e = t0.p_eb_e;
  const Geodetic llh = geodetic_from_ecef(t0.p_eb_e);
  o.initial_yaw_rad = euler_from_R_n_b(R_e_n(llh.lat, llh.lon).transpose() * t0.R_e_b()).z();
  fusion::EngineInputs in;
  in.imu = &s->imu;
  auto r = fusion::run_forward(in, o);
  if (!r || r->epochs.empty()) {
    std::fprintf(stderr, "%s\n", r ? "no output epoch" : r.error().message.c_str());
    return 1;
  }
  const Eigen::Vector3d end_truth = s->truth.nav.back().p_eb_e;
  const Eigen::Vector3d enu = enu_from_ecef(r->epochs.back().nav.p_eb_e, end_truth);
  const double err = std::hypot(enu.x(), enu.y());
  const double walked = s->antenna.empty() ? 0.0 : s->antenna.back().route_m;
  std::printf("consumer: %zu epochs, final horizontal error %.3f m after %.1f m (%.2f %%)\n", r->epochs.size(), err,
              walked, walked > 0 ? 100.0 * err / walked : 0.0);
  return walked > 0 && err < 0.01 * walked ? 0 : 1;
}
