// SPDX-License-Identifier: BSD-2-Clause
// IMU error model of the simulator (docs/sim.md §4): measured = saturate(quantize(M (I + S) x + b(t) + G f + n)).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "ins/imu.hpp"
#include "sim/scenario.hpp"

namespace pednav::sim {

/// The random constants drawn for one IMU (recorded so tests and users can compare estimates with them).
struct ImuErrorTruth {
  Eigen::Vector3d b_g0 = Eigen::Vector3d::Zero();  ///< turn-on gyro bias [rad/s]
  Eigen::Vector3d b_g_first = Eigen::Vector3d::Zero();  ///< total gyro bias at the first sample (turn-on + drift) [rad/s]
  Eigen::Vector3d b_a0 = Eigen::Vector3d::Zero();  ///< turn-on accelerometer bias [m/s^2]
  Eigen::Vector3d s_g = Eigen::Vector3d::Zero();   ///< gyro scale-factor errors [-]
  Eigen::Vector3d s_a = Eigen::Vector3d::Zero();   ///< accelerometer scale-factor errors [-]
  Eigen::Matrix3d M_g = Eigen::Matrix3d::Identity();  ///< gyro axis misalignment (I + small off-diagonals)
  Eigen::Matrix3d M_a = Eigen::Matrix3d::Identity();  ///< accelerometer axis misalignment
  Eigen::Matrix3d G_g = Eigen::Matrix3d::Zero();   ///< gyro g-sensitivity [rad/s per m/s^2]
  long saturated_samples = 0;                      ///< samples with an axis clipped at the range
};

/// Apply the error model of `options` to exact samples (deterministic from `seed`). With options.errors false
/// the samples are returned unchanged.
std::vector<ins::ImuSample> corrupt_imu(const std::vector<ins::ImuSample>& exact, const ImuOptions& options,
                                        uint64_t seed, ImuErrorTruth* truth);

}  // namespace pednav::sim
