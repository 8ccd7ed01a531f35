// SPDX-License-Identifier: BSD-2-Clause
// Trajectories and their comparison against a reference: errors in ENU at the reference, the statistics of
// DESIGN.md's evaluation.json (seed 004 Tables 1-2 bins), loop closure, and optional alignment for references
// in a local frame (e.g. Vicon).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "core/expected.hpp"
#include "core/time.hpp"

namespace pednav::eval {

/// One position of a trajectory.
struct TrajectoryPoint {
  GpsTime t;
  Eigen::Vector3d p;  ///< ECEF [m] (Frame::kEcef) or local ENU [m] (Frame::kLocalEnu)
  /// The solution's own 1σ East, North, Up [m] where the file gives it (pednav CSV sd_e_m, sd_n_m, sd_d_m), else NaN.
  Eigen::Vector3d sd_enu_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

enum class Frame { kEcef, kLocalEnu };

/// A time-ordered trajectory (strictly increasing times).
struct Trajectory {
  Frame frame = Frame::kEcef;
  std::vector<TrajectoryPoint> points;
};

/// How a solution is put into the reference's frame before differencing.
enum class Align {
  kNone,        ///< no alignment (both in ECEF)
  kStart,       ///< translate to a common start, rotate about the vertical to match the direction to the first
                ///< reference point >= 1 m from the start
  kStartPyshoe, ///< PyShoe's align_plots: translate to a common start, rotate about the vertical so that at the
                ///< first matched epoch >= 0.8 m (horizontal) from the *solution's* start both point the same way
                ///< (none within reach: the epoch 1.5 s after the start, PyShoe's sample 300 at 200 Hz)
  kBestFit2d,   ///< least-squares rotation about the vertical + 3D translation
  kBestFit3d,   ///< least-squares 3D rotation + translation (Horn/Umeyama, no scale)
};

struct CompareOptions {
  double time_tolerance_s = 0.05;   ///< a solution epoch matches a reference epoch this close in time
  double max_interp_gap_s = 1.5;    ///< else the reference is interpolated linearly between epochs this close
  Align align = Align::kNone;
  bool loop = false;                ///< report closure (start-to-end distance) of the solution
};

/// Error of one matched epoch, in ENU at the reference position [m] (solution - reference).
struct EpochError {
  GpsTime t;
  Eigen::Vector3d d_enu;
  double horizontal_m = 0.0;
  /// The solution's 1σ E, N, U at this epoch [m] (NaN when unknown), in the solution's own axes: with an alignment
  /// that rotates about the vertical, σ_h = √(σ_E² + σ_N²) still applies but the per-axis values do not.
  Eigen::Vector3d sd_enu_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

/// The statistics of evaluation.json (DESIGN.md) plus the matched epochs.
struct Evaluation {
  int epochs_compared = 0;
  int reference_epochs = 0;          ///< reference epochs inside the solution's time span (+- tolerance)
  double availability_pct = 0.0;     ///< matched / reference_epochs
  double horizontal_rms_m = 0.0, horizontal_mean_m = 0.0, horizontal_p50_m = 0.0, horizontal_p95_m = 0.0,
         horizontal_max_m = 0.0;
  double vertical_rms_m = 0.0, vertical_mean_m = 0.0, vertical_max_abs_m = 0.0;
  double bins_pct[4] = {0, 0, 0, 0};  ///< horizontal error < 5, 5-10, 10-20, >= 20 m (seed 004 Tables 1-2)
  bool has_closure = false;
  double closure_m = 0.0, distance_m = 0.0, closure_pct_of_distance = 0.0;
  std::vector<EpochError> errors;
  Eigen::Matrix3d R_align = Eigen::Matrix3d::Identity();  ///< applied to solution ENU when aligning
  Eigen::Vector3d t_align = Eigen::Vector3d::Zero();
};

/// Compare a solution with a reference. Fails when no epoch overlaps (message names both spans).
Expected<Evaluation> compare(const Trajectory& solution, const Trajectory& reference, const CompareOptions& options);

/// Empirical quantile (linear interpolation between order statistics) of unsorted values, q in [0, 1].
double quantile(std::vector<double> values, double q);

/// Horizontal path length [m] of a trajectory (ENU about its first point for ECEF input).
double path_length_horizontal_m(const Trajectory& t);

}  // namespace pednav::eval
