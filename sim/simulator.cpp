// SPDX-License-Identifier: BSD-2-Clause
// Simulator driver (docs/sim.md): plan -> walk truth + exact IMU -> IMU errors -> antenna -> GNSS.
#include "sim/simulator.hpp"

#include <memory>

#include "sim/constellation.hpp"

namespace pednav::sim {

AntennaFunction antenna_function(const Scenario& sc, const LocalFrame& frame, const StridePlan& plan) {
  if (sc.imu.carry == "hand") {  // the device's own antenna: the hand track (docs/sim.md §9)
    auto hand = std::make_shared<HandTrack>(sc, plan);
    const GpsTime t0 = sc.start;
    return [hand, frame, t0](GpsTime t) {
      constexpr double h = 1e-3;
      const double ts = t - t0;
      const HandPose a = hand->at(ts - h), b = hand->at(ts), c = hand->at(ts + h);
      AntennaTruth r;
      r.p_e = frame.to_e(b.p_n0);
      r.v_e = frame.R_e_n0 * (c.p_n0 - a.p_n0) / (2.0 * h);
      r.route_m = b.route_m;
      return r;
    };
  }
  auto body = std::make_shared<BodyTrack>(plan, sc.gnss.antenna_height_m, sc.gnss.antenna_bob_m);
  const GpsTime t0 = sc.start;
  return [body, frame, t0](GpsTime t) {
    Eigen::Vector3d p, v;
    AntennaTruth a;
    body->antenna_n0(t - t0, p, v, a.route_m);
    a.p_e = frame.to_e(p);
    a.v_e = frame.R_e_n0 * v;
    return a;
  };
}

Expected<Simulation> simulate(const Scenario& scenario) {
  if (auto p = scenario.problems(); !p.empty()) {
    std::string m = "scenario";
    if (!scenario.name.empty()) m += " " + scenario.name;
    m += ":";
    for (const auto& s : p) m += " " + s + ";";
    m.pop_back();
    return make_error(m);
  }
  Simulation sim;
  sim.scenario = scenario;
  if (!scenario.track.empty()) {
    // Along-a-track mode: the origin is the ground under the first track point.
    Geodetic o = geodetic_from_ecef(scenario.track.front().p_e);
    o.h_m -= scenario.gnss.antenna_height_m;
    sim.scenario.origin = o;
  }
  sim.frame = local_frame(sim.scenario.origin);
  auto plan = scenario.track.empty() ? plan_route(sim.scenario, sim.frame) : plan_track(sim.scenario, sim.frame);
  if (!plan) return plan.error();
  sim.plan = std::move(*plan);
  sim.truth = scenario.imu.carry == "hand" ? synthesize_hand(sim.scenario, sim.frame, sim.plan)
                                            : synthesize_walk(sim.scenario, sim.frame, sim.plan);
  sim.imu = corrupt_imu(sim.truth.imu, scenario.imu, scenario.seed, &sim.imu_errors);
  const AntennaFunction ant = antenna_function(sim.scenario, sim.frame, sim.plan);
  sim.antenna.reserve(sim.truth.nav.size());
  for (const auto& x : sim.truth.nav) sim.antenna.push_back(ant(x.t));
  const GpsTime t_end = sim.truth.nav.back().t;
  if (scenario.gnss.enabled && scenario.track.empty()) {
    sim.has_gnss = true;
    sim.nav = nominal_gps_constellation(scenario.gnss.satellites, scenario.start, t_end, scenario.seed);
    const Eigen::Vector3d& b = scenario.gnss.base_offset_enu_m;
    const Eigen::Vector3d base_n0(b.y(), b.x(), -(b.z() + scenario.gnss.base_antenna_height_m));
    sim.gnss = simulate_gnss(scenario.gnss, sim.nav, ant, sim.frame.to_e(base_n0), scenario.start, t_end, scenario.seed);
  }
  return sim;
}

}  // namespace pednav::sim
