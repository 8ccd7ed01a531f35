// SPDX-License-Identifier: BSD-2-Clause
// WGS84 geodesy: ECEF <-> geodetic, the NED frame at a point, local offsets.
#pragma once

#include <Eigen/Core>

namespace pednav {

namespace wgs84 {
inline constexpr double kA_m = 6378137.0;                    ///< semi-major axis
inline constexpr double kF = 1.0 / 298.257223563;            ///< flattening
inline constexpr double kE2 = kF * (2.0 - kF);               ///< first eccentricity squared
inline constexpr double kB_m = kA_m * (1.0 - kF);            ///< semi-minor axis
inline constexpr double kOmegaIE_radps = 7.2921151467e-5;    ///< Earth rotation rate (IS-GPS-200)
inline constexpr double kGM_m3ps2 = 3.986004418e14;          ///< gravitational constant (WGS84)
inline constexpr double kJ2 = 1.082627e-3;                   ///< second zonal harmonic (Groves 2013 eq. 2.140)
}  // namespace wgs84

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDegToRad = kPi / 180.0;
inline constexpr double kRadToDeg = 180.0 / kPi;
inline constexpr double kSpeedOfLight_mps = 299792458.0;

/// Geodetic coordinates: latitude and longitude [rad], ellipsoidal height [m] (WGS84).
struct Geodetic {
  double lat = 0.0;
  double lon = 0.0;
  double h_m = 0.0;
};

/// ECEF position [m] of a geodetic point (Groves 2013 eq. 2.112).
Eigen::Vector3d ecef_from_geodetic(const Geodetic& llh);
/// Geodetic coordinates of an ECEF position [m]; accurate to < 1e-6 m for heights -1 km .. 100 km, poles included.
Geodetic geodetic_from_ecef(const Eigen::Vector3d& p_e);
/// Rotation from local NED to ECEF at latitude/longitude [rad]: v_e = R_e_n * v_n (Groves eq. 2.150).
Eigen::Matrix3d R_e_n(double lat, double lon);
/// NED offset [m] of p_e from the reference point p_ref_e (both ECEF [m]), resolved at the reference.
Eigen::Vector3d ned_from_ecef(const Eigen::Vector3d& p_e, const Eigen::Vector3d& p_ref_e);
/// ENU offset [m] of p_e from the reference point p_ref_e (both ECEF [m]).
Eigen::Vector3d enu_from_ecef(const Eigen::Vector3d& p_e, const Eigen::Vector3d& p_ref_e);
/// ECEF position [m] of a NED offset [m] from the reference point p_ref_e.
Eigen::Vector3d ecef_from_ned(const Eigen::Vector3d& d_n, const Eigen::Vector3d& p_ref_e);
/// Meridian (north-south) and transverse (east-west) radii of curvature [m] at latitude [rad].
void radii_of_curvature(double lat, double& r_n_m, double& r_e_m);

}  // namespace pednav
