// SPDX-License-Identifier: BSD-2-Clause
#include "core/geodesy.hpp"

#include <cmath>

namespace pednav {

Eigen::Vector3d ecef_from_geodetic(const Geodetic& llh) {
  const double s = std::sin(llh.lat), c = std::cos(llh.lat);
  const double n = wgs84::kA_m / std::sqrt(1.0 - wgs84::kE2 * s * s);  // transverse radius
  return {(n + llh.h_m) * c * std::cos(llh.lon), (n + llh.h_m) * c * std::sin(llh.lon),
          (n * (1.0 - wgs84::kE2) + llh.h_m) * s};
}

Geodetic geodetic_from_ecef(const Eigen::Vector3d& p_e) {
  // Fixed-point iteration on lat = atan2(z + e^2 N sin(lat), p); the height uses the form
  // h = p cos(lat) + z sin(lat) - a sqrt(1 - e^2 sin^2 lat), regular at the poles and the equator.
  const double x = p_e.x(), y = p_e.y(), z = p_e.z();
  const double p = std::hypot(x, y);
  Geodetic g;
  g.lon = (p > 0.0) ? std::atan2(y, x) : 0.0;
  double lat = std::atan2(z, p * (1.0 - wgs84::kE2));
  for (int i = 0; i < 12; ++i) {
    const double s = std::sin(lat);
    const double n = wgs84::kA_m / std::sqrt(1.0 - wgs84::kE2 * s * s);
    const double next = std::atan2(z + wgs84::kE2 * n * s, p);
    const bool done = std::abs(next - lat) < 1e-15;
    lat = next;
    if (done) break;
  }
  const double s = std::sin(lat), c = std::cos(lat);
  g.lat = lat;
  g.h_m = p * c + z * s - wgs84::kA_m * std::sqrt(1.0 - wgs84::kE2 * s * s);
  return g;
}

Eigen::Matrix3d R_e_n(double lat, double lon) {
  const double sl = std::sin(lat), cl = std::cos(lat), so = std::sin(lon), co = std::cos(lon);
  Eigen::Matrix3d r;
  // Columns: north, east, down unit vectors resolved in ECEF.
  r << -sl * co, -so, -cl * co,
       -sl * so, co, -cl * so,
       cl, 0.0, -sl;
  return r;
}

Eigen::Vector3d ned_from_ecef(const Eigen::Vector3d& p_e, const Eigen::Vector3d& p_ref_e) {
  const Geodetic ref = geodetic_from_ecef(p_ref_e);
  return R_e_n(ref.lat, ref.lon).transpose() * (p_e - p_ref_e);
}

Eigen::Vector3d enu_from_ecef(const Eigen::Vector3d& p_e, const Eigen::Vector3d& p_ref_e) {
  const Eigen::Vector3d ned = ned_from_ecef(p_e, p_ref_e);
  return {ned.y(), ned.x(), -ned.z()};
}

Eigen::Vector3d ecef_from_ned(const Eigen::Vector3d& d_n, const Eigen::Vector3d& p_ref_e) {
  const Geodetic ref = geodetic_from_ecef(p_ref_e);
  return p_ref_e + R_e_n(ref.lat, ref.lon) * d_n;
}

void radii_of_curvature(double lat, double& r_n_m, double& r_e_m) {
  const double s2 = std::sin(lat) * std::sin(lat);
  const double d = 1.0 - wgs84::kE2 * s2;
  r_n_m = wgs84::kA_m * (1.0 - wgs84::kE2) / std::pow(d, 1.5);
  r_e_m = wgs84::kA_m / std::sqrt(d);
}

}  // namespace pednav
