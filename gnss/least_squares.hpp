// SPDX-License-Identifier: BSD-2-Clause
// Epoch-by-epoch weighted least squares: position + one receiver clock per constellation from code, then
// velocity + clock drift from Doppler, each with fault detection and exclusion (global chi-square test, then
// worst normalized residual first while redundancy allows). Single-differenced (rover - base) when a base
// epoch is given, otherwise undifferenced with broadcast clock, Klobuchar and Saastamoinen. docs/gnss.md.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "core/time.hpp"
#include "gnss/measurement.hpp"
#include "gnss/types.hpp"

namespace pednav::gnss {

/// Why a satellite of an epoch was not used (counted per epoch and summed in summary.json).
enum class RejectReason : int {
  kNoPseudorange = 0,   ///< rover record without code (Doppler only)
  kLowCn0,              ///< below min_cn0_dbhz
  kNoEphemeris,         ///< no healthy broadcast ephemeris within its validity
  kNotAtBase,           ///< SD: the base epoch lacks this satellite's code
  kBelowElevationMask,  ///< below the elevation mask at the rover
  kCodeFault,           ///< excluded by code fault detection
  kDopplerFault,        ///< Doppler excluded by fault detection (the code may still be used)
  kCount
};
/// snake_case name of a reason (summary.json key).
const char* reject_reason_name(RejectReason r);

/// Why an epoch has no position (summary.json key via epoch_failure_name).
enum class EpochFailure : int { kNone = 0, kNoBaseEpoch, kTooFewSatellites, kNotConverged, kCount };
const char* epoch_failure_name(EpochFailure f);

struct SolverOptions {
  double elevation_mask_rad = 10.0 * kDegToRad;
  double min_cn0_dbhz = 0.0;
  double fault_probability = 0.999;  ///< chi-square test probability of the global and local tests
  WeightModel weights;
  int max_iterations = 10;
  double convergence_m = 1e-4;       ///< stop Gauss-Newton when the position step is below this [m]
};

/// Dilution of precision (unweighted geometry, ENU at the solution).
struct Dops {
  double gdop = 0.0, pdop = 0.0, hdop = 0.0, vdop = 0.0;
};

/// Solution of one rover epoch.
struct EpochSolution {
  GpsTime time;                       ///< rover epoch time tag (GPST)
  EpochFailure failure = EpochFailure::kNone;
  bool velocity_ok = false;
  Eigen::Vector3d p_ea_e = Eigen::Vector3d::Zero();  ///< antenna position [m], ECEF
  Eigen::Vector3d v_ea_e = Eigen::Vector3d::Zero();  ///< antenna velocity [m/s], ECEF
  Eigen::Matrix3d cov_p_e = Eigen::Matrix3d::Zero(); ///< position covariance [m^2], ECEF
  Eigen::Matrix3d cov_v_e = Eigen::Matrix3d::Zero(); ///< velocity covariance [m^2/s^2], ECEF
  std::vector<std::pair<System, double>> clock_m;     ///< c*dt per constellation [m] (SD: rover - base)
  double drift_mps = 0.0;                             ///< c*d(dt)/dt [m/s]
  Dops dops;
  int n_sats_used = 0;        ///< satellites in the final code solution
  int n_sats_rejected = 0;    ///< code fault exclusions in this epoch
  int n_doppler_used = 0;
  bool global_test_passed = true;  ///< code residuals consistent with the weight model after exclusions
  std::vector<SatId> used;
  std::array<int, static_cast<int>(RejectReason::kCount)> rejections{};
  bool ok() const { return failure == EpochFailure::kNone; }
};

/// Solve one rover epoch. `base` (nullable) = the matched base epoch (its own time tag) with the base antenna at
/// p_eb_e [m, ECEF]; p_init_e = linearisation start [m, ECEF] (zero: start from the Earth's centre).
/// Klobuchar coefficients are used in undifferenced mode only (all zero = no ionosphere model).
EpochSolution solve_epoch(const NavData& nav, const ObsEpoch& rover, const ObsEpoch* base,
                          const Eigen::Vector3d& p_eb_e, const Eigen::Vector3d& p_init_e, const SolverOptions& options);

/// Quantile of the chi-square distribution with `dof` degrees of freedom at probability p (0 < p < 1).
double chi_square_quantile(double p, int dof);

}  // namespace pednav::gnss
