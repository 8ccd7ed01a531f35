// SPDX-License-Identifier: BSD-2-Clause
// GNSS code and Doppler measurement models (undifferenced and single-differenced rover - base) with Jacobians
// w.r.t. the rover antenna position/velocity and the receiver clock/drift. Shared by the epoch least squares
// (gnss/least_squares.*) and the tightly coupled EKF (fusion/). Model and sign conventions: docs/gnss.md.
#pragma once

#include <Eigen/Core>
#include <array>

#include "core/expected.hpp"
#include "core/geodesy.hpp"
#include "core/time.hpp"
#include "gnss/ephemeris.hpp"
#include "gnss/types.hpp"

namespace pednav::gnss {

/// Satellite state at the transmit time of a signal received at t_rx with pseudorange P:
/// t_tx = t_rx - P/c - dt_s(t_tx) (two clock iterations; IS-GPS-200 20.3.3.3.3.1). Position in ECEF of t_tx.
Expected<SatState> satellite_state_at_reception(const NavData& nav, SatId sat, GpsTime t_rx, double pseudorange_m);

/// Geometry receiver -> satellite with the Sagnac (Earth rotation during signal flight) correction
/// (Groves 2013 eq. 8.34-8.35, linearised rotation, error < 1 mm for terrestrial receivers).
struct LineOfSight {
  double range_m = 0.0;                                  ///< Sagnac-corrected geometric range [m]
  double range_rate_mps = 0.0;                           ///< its time derivative [m/s]
  Eigen::Vector3d u_as_e = Eigen::Vector3d::Zero();      ///< unit vector antenna -> satellite, ECEF
  Eigen::RowVector3d J_range_p = Eigen::RowVector3d::Zero();  ///< d range / d p_ea_e
  Eigen::RowVector3d J_rate_p = Eigen::RowVector3d::Zero();   ///< d range_rate / d p_ea_e [1/s]
  Eigen::RowVector3d J_rate_v = Eigen::RowVector3d::Zero();   ///< d range_rate / d v_ea_e
};
/// Line of sight from antenna position p_ea_e [m, ECEF] moving at v_ea_e [m/s, ECEF] to a satellite.
LineOfSight line_of_sight(const SatState& sat, const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& v_ea_e);

/// Elevation and azimuth [rad] of p_es_e seen from p_ea_e (both ECEF [m]); azimuth from north, clockwise.
struct ElevationAzimuth {
  double elevation = 0.0;
  double azimuth = 0.0;
};
ElevationAzimuth elevation_azimuth(const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& p_es_e);

/// One linearised measurement: residual = measured - predicted, and the Jacobian of the prediction w.r.t.
/// rover antenna position p_ea_e, velocity v_ea_e, the receiver clock term c*dt [m] (of the satellite's
/// constellation) and drift c*d(dt)/dt [m/s]. Blocks a model does not touch are zero.
struct MeasurementRow {
  SatId sat;
  double residual = 0.0;
  Eigen::RowVector3d J_p = Eigen::RowVector3d::Zero();
  Eigen::RowVector3d J_v = Eigen::RowVector3d::Zero();
  double J_clock = 0.0;
  double J_drift = 0.0;
};

/// One satellite's signal at one receiver: the measurement and the satellite state at its transmit time.
struct SignalAtReceiver {
  double pseudorange_m = kNaN;   ///< P [m]
  double range_rate_mps = kNaN;  ///< -lambda * Doppler [m/s]
  SatState sat;                  ///< at this signal's transmit time
};

/// Undifferenced pseudorange: P = rho + c dt_r - c (dt_s - TGD) + I + T (IS-GPS-200 20.3.3.3.3.2).
/// iono_m/tropo_m are the modelled delays [m] (Klobuchar/Saastamoinen), clock_m = c dt_r [m].
MeasurementRow ud_pseudorange(SatId sat, const SignalAtReceiver& s, const Eigen::Vector3d& p_ea_e, double clock_m,
                              double iono_m, double tropo_m);
/// Undifferenced range rate: -lambda D = u.(v_s - v_a) (+ Sagnac rate) + c d(dt_r)/dt - c d(dt_s)/dt.
MeasurementRow ud_range_rate(SatId sat, const SignalAtReceiver& s, const Eigen::Vector3d& p_ea_e,
                             const Eigen::Vector3d& v_ea_e, double drift_mps);

/// Single-differenced pseudorange rover - base (DESIGN.md): P_r - P_b = rho_r - rho_b - c(dt_s(t_tx,r) -
/// dt_s(t_tx,b)) + c dt_rb. The base antenna is static at p_eb_e [m, ECEF]; clock_rb_m = c dt_rb [m].
MeasurementRow sd_pseudorange(SatId sat, const SignalAtReceiver& rover, const SignalAtReceiver& base,
                              const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& p_eb_e, double clock_rb_m);
/// Single-differenced range rate: -lambda(D_r - D_b) = e_r.(v_s - v_r) - e_b.v_s - c(d dt_s,r - d dt_s,b) + c d dt_rb.
MeasurementRow sd_range_rate(SatId sat, const SignalAtReceiver& rover, const SignalAtReceiver& base,
                             const Eigen::Vector3d& p_ea_e, const Eigen::Vector3d& v_ea_e,
                             const Eigen::Vector3d& p_eb_e, double drift_rb_mps);

/// Klobuchar ionospheric delay on GPS L1 [m] (IS-GPS-200 20.3.3.5.2.5) at GPST t for a receiver at `llh`
/// and a satellite at elevation/azimuth [rad]; coefficients alpha0..3, beta0..3 as broadcast.
double klobuchar_delay_m(const std::array<double, 8>& alpha_beta, GpsTime t, const Geodetic& llh,
                         const ElevationAzimuth& el_az);
/// Saastamoinen tropospheric delay [m] with the standard atmosphere (Saastamoinen 1972; 15 C and 1013.25 hPa at
/// sea level, 70 % humidity) at elevation [rad].
double saastamoinen_delay_m(const Geodetic& llh, double elevation_rad);

/// Code and Doppler noise model (docs/gnss.md "Weighting", eq. W1): sigma = sigma_zenith * 10^((cn0_ref - C/N0)/20)
/// * sqrt(1 + k (1/sin^2(el) - 1)), the C/N0 factor applied only below cn0_ref; a missing C/N0 counts as cn0_ref.
/// Eq. W2: the code sigma times sqrt((1 + b c^2) / (1 + b)) when code_squaring_loss b > 0.
/// k = elevation_weight: 1 gives sigma_zenith * c / sin(el) (RTKLIB's form), 0 the C/N0 factor alone.
struct WeightModel {
  double code_sigma_zenith_m = 0.4;      ///< code noise at zenith and C/N0 >= cn0_ref [m]
  double doppler_sigma_zenith_mps = 0.05;///< range-rate noise at zenith and C/N0 >= cn0_ref [m/s]
  double cn0_ref_dbhz = 45.0;            ///< C/N0 above which noise no longer decreases [dB-Hz]
  double min_elevation_for_weight_rad = 5.0 * kDegToRad;  ///< 1/sin(el) is capped at this elevation
  double glonass_code_factor = 3.0;      ///< GLONASS code sigma / GPS (x2 chip length, x1.5 FDMA biases)
  double elevation_weight = 1.0;         ///< k of eq. W1, in [0, 1]: the share of the 1/sin^2(el) variance factor
  /// b of eq. W2: the DLL squaring loss at cn0_ref (2 / ((2 − d) T C/N0_ref) for correlator spacing d [chips] and
  /// coherent integration T [s]); the code variance gets (1 + b c²) / (1 + b), c = the C/N0 factor. 0: off.
  double code_squaring_loss = 0.0;
};
/// Standard deviation [m or m/s] of one receiver's code (doppler=false) or range rate (doppler=true).
double measurement_sigma(const WeightModel& model, double cn0_dbhz, double elevation_rad, bool doppler);

}  // namespace pednav::gnss
