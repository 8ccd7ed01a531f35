// SPDX-License-Identifier: BSD-2-Clause
// Shared pieces of the GNSS-only kinematic filters (fusion/kinematic_model.hpp).
#include "fusion/kinematic_model.hpp"

#include <Eigen/Cholesky>
#include <algorithm>

#include "core/geodesy.hpp"

namespace pednav::fusion {

void predict_white_acceleration(Eigen::VectorXd& x, Eigen::MatrixXd& P, double dt, double sigma_h, double sigma_v) {
  // Eq. 4.1: p += v dt; Q from the acceleration PSD in the local level frame.
  const int n = static_cast<int>(x.size());
  x.segment<3>(0) += x.segment<3>(3) * dt;
  Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(n, n);
  Phi.block<3, 3>(0, 3) = Eigen::Matrix3d::Identity() * dt;
  P = Phi * P * Phi.transpose();
  const Geodetic llh = geodetic_from_ecef(x.segment<3>(0));
  const Eigen::Matrix3d Ren = R_e_n(llh.lat, llh.lon);
  const double qh = sigma_h * sigma_h, qv = sigma_v * sigma_v;
  const Eigen::Matrix3d Qa = Ren * Eigen::Vector3d(qh, qh, qv).asDiagonal() * Ren.transpose();
  P.block<3, 3>(0, 0) += Qa * dt * dt * dt / 3.0;
  P.block<3, 3>(0, 3) += Qa * dt * dt / 2.0;
  P.block<3, 3>(3, 0) += Qa * dt * dt / 2.0;
  P.block<3, 3>(3, 3) += Qa * dt;
}

bool w_test_pass_solve(const Eigen::MatrixXd& P, WTestPass& pass) {
  const int m = static_cast<int>(pass.act.size());
  pass.PHt = P * pass.H.transpose();
  Eigen::MatrixXd S = pass.H * pass.PHt;
  S.diagonal() += pass.R;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
  if (ldlt.info() != Eigen::Success) return false;
  pass.Sinv = ldlt.solve(Eigen::MatrixXd::Identity(m, m));
  return true;
}

void joseph_update(const Eigen::MatrixXd& P, const WTestPass& pass, Eigen::VectorXd& dx, Eigen::MatrixXd& P_post) {
  const Eigen::MatrixXd K = pass.PHt * pass.Sinv;
  dx = K * pass.r;
  const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(P.rows(), P.cols()) - K * pass.H;
  P_post = IKH * P * IKH.transpose() + K * pass.R.asDiagonal() * K.transpose();
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

int system_slot(const std::vector<gnss::System>& systems, gnss::System s) {
  for (size_t i = 0; i < systems.size(); ++i) {
    if (systems[i] == s) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace pednav::fusion
