// SPDX-License-Identifier: BSD-2-Clause
// Saturated (clipped) IMU samples: find the runs of samples held at the full scale, reconstruct the clipped part
// from the samples around each run, and say how uncertain the reconstruction is (docs/ins.md §9).
//
// A foot's swing can exceed a MEMS gyro's range (the Crista's 300 °/s: the across-foot rate of a 1.2 m/s walk peaks
// near 460 °/s). The clipped samples lose a few degrees of pitch per swing; the filter's error model does not know
// that, so it blames whatever states it has (biases, scale factors) and its σ stops being honest. Here every run of
// samples at the full scale on one axis is replaced by a least-squares polynomial through the unclipped samples on
// both sides, and the angle (gyro) or velocity (accelerometer) the run adds gets a σ for the filter's process noise.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ins/imu.hpp"

namespace pednav::ins {

/// How saturated samples are found and repaired.
struct SaturationOptions {
  double gyro_range_radps = 0.0;   ///< full scale of each gyro axis [rad/s] (0: unknown, not checked)
  double accel_range_mps2 = 0.0;   ///< full scale of each accelerometer axis [m/s^2] (0: not checked)
  double level = 0.999;            ///< a sample with |value| >= level x range is clipped
  int fit_samples = 4;             ///< unclipped samples used on each side of a run
  double max_run_s = 0.25;         ///< longer runs are not reconstructed (the extrapolation is not trusted)
  double max_peak_factor = 3.0;    ///< reconstructed values are capped at this x range
  double sigma_fraction = 0.25;    ///< σ of a run's added angle/velocity: at least this fraction of it (eq. 9.3)
};

/// One run of consecutive samples clipped on one axis of one sensor.
struct SaturatedRun {
  size_t first = 0, last = 0;   ///< sample indices (inclusive)
  bool gyro = true;             ///< gyro (rad, rad/s) or accelerometer (m/s, m/s^2)
  int axis = 0;                 ///< sensor axis 0..2
  bool reconstructed = false;   ///< false: too long, at the edge of the log, or too close to another run
  double added = 0.0;           ///< ∫ (reconstructed − clipped) dt over the run [rad or m/s] (0 if not reconstructed)
  double sigma = 0.0;           ///< σ of the run's angle/velocity error after the repair [rad or m/s]
};

/// The repaired samples (indices into the input, ascending) and the runs.
struct SaturationRepair {
  struct Sample {
    size_t index = 0;
    Eigen::Vector3d omega_ib_b = Eigen::Vector3d::Zero();
    Eigen::Vector3d f_ib_b = Eigen::Vector3d::Zero();
  };
  std::vector<Sample> samples;     ///< one entry per sample with any clipped axis
  std::vector<SaturatedRun> runs;  ///< ordered by last sample index
  /// Non-empty when a sensor's check was switched off because the data exceed its range (the configured range
  /// is then not the device's: nothing of that sensor is treated as clipped).
  std::vector<std::string> notes;
};

/// Find and repair the saturated samples of a time-ordered log (docs/ins.md eq. 9.1-9.3).
SaturationRepair repair_saturation(const std::vector<ImuSample>& samples, const SaturationOptions& options);

}  // namespace pednav::ins
