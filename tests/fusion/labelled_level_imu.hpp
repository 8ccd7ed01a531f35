// SPDX-License-Identifier: BSD-2-Clause
// A level IMU (FRD body = NED, yaw 0) at 200 Hz near Toronto, noise-free, whose stance is given as labels
// (zupt.detector labels), run in ins mode with the GX5-25 spec: the scenario tests of what the engine makes of a
// stance that is not static (ZARU gate, initial gyro bias from the first still period).
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/geodesy.hpp"
#include "fusion/engine.hpp"
#include "ins/imu_spec.hpp"

namespace pednav::test {

struct LabelledLevelImu {
  double duration_s = 6.0;
  double no_stance_from_s = 2.5;  ///< the one non-stance span [from, to): it ends the levelling window
  double no_stance_to_s = 2.6;
  bool earth_rate = false;        ///< add the Earth rate to the gyro (then a true bias is what the filter should find)
  std::function<Eigen::Vector3d(double t_s)> rate_b = [](double) { return Eigen::Vector3d::Zero(); };  ///< [rad/s]
};

inline constexpr double kLabelledLevelImuLat_rad = 43.78 * kDegToRad;

inline fusion::EngineOptions labelled_level_imu_options() {
  fusion::EngineOptions o;
  o.mode = fusion::Mode::kInsOnly;
  o.spec = *ins::imu_spec_preset("gx5_25");
  o.initial_position_e = ecef_from_geodetic(Geodetic{kLabelledLevelImuLat_rad, -79.47 * kDegToRad, 190.0});
  o.initial_yaw_rad = 0.0;
  o.zupt.detector = "labels";
  return o;
}

inline Expected<fusion::EngineResult> run_labelled_level_imu(const LabelledLevelImu& s, const fusion::EngineOptions& o) {
  constexpr double kRateHz = 200.0;
  const double lat = kLabelledLevelImuLat_rad;
  const Eigen::Vector3d earth_b = s.earth_rate
                                      ? Eigen::Vector3d(wgs84::kOmegaIE_radps * std::cos(lat), 0.0,
                                                        -wgs84::kOmegaIE_radps * std::sin(lat))
                                      : Eigen::Vector3d::Zero();
  std::vector<ins::ImuSample> imu;
  std::vector<uint8_t> labels;
  const GpsTime t0 = GpsTime::from_week_tow(2300, 100000.0);
  for (int i = 0; i < static_cast<int>(s.duration_s * kRateHz); ++i) {
    const double t = i / kRateHz;
    ins::ImuSample x;
    x.t = t0.plus_ns(static_cast<int64_t>(i) * 5'000'000);
    x.f_ib_b = Eigen::Vector3d(0.0, 0.0, -9.80665);
    x.omega_ib_b = earth_b + s.rate_b(t);
    imu.push_back(x);
    labels.push_back(t >= s.no_stance_from_s - 1e-9 && t < s.no_stance_to_s - 1e-9 ? 0 : 1);
  }
  fusion::EngineInputs in;
  in.imu = &imu;
  in.stance_labels = &labels;
  return fusion::run_forward(in, o);
}

}  // namespace pednav::test
